use super::*;

#[test]
fn shares_of_a_file_hold_each_row_once_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rows.csv");
    let mut text = String::from("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n");
    for k in 0..37 {
        // Rows of different lengths, so that the shares' edges fall anywhere in them.
        text += &format!("{}.{},0,0,0.5,0,0,0,1,0,0,0,0,0,0\n", k, "7".repeat(k % 5));
    }
    std::fs::write(&path, &text).unwrap();
    let limits = Limits {
        materials: 1,
        radius_min: 0.5,
        radius_max: 0.5,
    };
    let whole = load_particles_within(&path, &limits).unwrap();
    for n in 1..=7 {
        let mut x = Vec::new();
        for k in 0..n {
            let (p, clumps, ids) = load_grains_share(&path, &limits, (k, n)).unwrap();
            assert!(clumps.is_none() && !ids);
            x.extend(p.x);
        }
        assert_eq!(x, whole.x, "{n} shares");
    }
}

#[test]
fn contact_networks_read_back_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let contacts = vec![
        ContactRecord {
            id: 3,
            with: Partner::Particle(7),
            point: DVec3::new(0.1, 0.2, 1.0 / 3.0),
            f_n: DVec3::new(0.0, 0.0, 1.5e-3),
            f_t: DVec3::new(-2e-5, 1e-300, 0.0),
            overlap: 1e-6,
            tau_i: DVec3::new(1e-9, -2e-8, 0.1),
            tau_j: DVec3::new(0.0, 3e-9, -1.0 / 7.0),
        },
        ContactRecord {
            id: 4,
            with: Partner::Face(12),
            point: DVec3::ZERO,
            f_n: DVec3::X,
            f_t: DVec3::ZERO,
            overlap: 0.0,
            tau_i: DVec3::ZERO,
            tau_j: DVec3::ZERO,
        },
    ];
    let path = write_contacts(dir.path(), "contacts000001.csv", &contacts).unwrap();
    assert_eq!(load_contacts(&path).unwrap(), contacts);
    let bad = |text: &str| {
        std::fs::write(&path, format!("{CONTACT_COLUMNS}\n{text}\n")).unwrap();
        format!("{:#}", load_contacts(&path).unwrap_err())
    };
    assert!(bad("1,2,3").contains(":2: 3 values"));
    let zeros = ",0".repeat(6);
    assert!(
        bad(&format!("1,2,3,0,0,0,0,0,0,0,0,0,0{zeros}")).contains("a particle (id_j, face = -1)")
    );
    assert!(bad(&format!("1,2,-1,0,0,nan,0,0,0,0,0,0,0{zeros}")).contains("'nan' is not a finite"));
    // A network of an earlier version, without the torques: read with none.
    std::fs::write(
        &path,
        format!("{CONTACT_COLUMNS_V1}\n4,-1,12,0,0,0,1,0,0,0,0,0,0\n"),
    )
    .unwrap();
    assert_eq!(load_contacts(&path).unwrap(), contacts[1..]);
}

#[test]
fn round_trip_is_exact() {
    let p: Particles = [Particle {
        x: DVec3::new(0.1, -1e-300, 1.0 / 3.0),
        radius: 0.004,
        v: DVec3::new(1e-7, 2.5, -0.0),
        q: DQuat::from_rotation_x(0.3),
        w: DVec3::new(1.0, 2.0, 3.0),
        tag: 42,
        ..Default::default()
    }]
    .into_iter()
    .collect();
    let mut text = Vec::new();
    write_particles(
        &mut text,
        &p,
        Extra {
            tag: true,
            ..Extra::default()
        },
    )
    .unwrap();
    let back = read_particles(&text[..], "t").unwrap();
    assert_eq!(back, p);
}

#[test]
fn ids_and_materials_round_trip() {
    let mut p: Particles = (0..3)
        .map(|k| Particle {
            x: DVec3::new(k as f64, 0.0, 0.0),
            radius: 0.004,
            material: k as u16,
            ..Default::default()
        })
        .collect();
    // Ids with gaps (particles 1, 4 and 6 removed), stored out of id order.
    p.id = vec![7, 2, 5];
    p.next_id = 8;
    let mut text = Vec::new();
    let extra = Extra {
        ids: true,
        ..Extra::default()
    };
    write_particles(&mut text, &p, extra).unwrap();
    let text = String::from_utf8(text).unwrap();
    assert!(text.starts_with("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,id,material\n1.0,"));
    let back = read_particles(text.as_bytes(), "t").unwrap();
    assert_eq!(back.id, vec![2, 5, 7]);
    assert_eq!(back.material, vec![1, 2, 0]);
    assert_eq!(back.next_id, 8);
    let twice = text.replace(",7,0\n", ",2,0\n");
    assert!(err(&twice).contains("particle id 2 appears twice"));
}

#[test]
fn fixed_particles_round_trip() {
    let mut p: Particles = (0..3)
        .map(|k| Particle {
            x: DVec3::new(k as f64, 0.0, 0.0),
            radius: 0.004,
            fixed: k == 1,
            ..Particle::default()
        })
        .collect();
    let mut text = Vec::new();
    write_particles(&mut text, &p, Extra::default()).unwrap();
    let text = String::from_utf8(text).unwrap();
    assert!(
        text.lines().next().unwrap().ends_with(",wz,fixed"),
        "{text}"
    );
    assert_eq!(read_particles(text.as_bytes(), "t").unwrap(), p);
    assert!(err(&text.replace(",1\n", ",2\n")).contains("p.csv:3: fixed = 2: expected 1"));
    // None fixed: no column, unless the run has fixed particles.
    p.fixed = vec![false; 3];
    let mut text = Vec::new();
    write_particles(&mut text, &p, Extra::default()).unwrap();
    assert!(!String::from_utf8(text).unwrap().contains("fixed"));
}

fn err(text: &str) -> String {
    format!(
        "{:#}",
        read_particles(text.as_bytes(), "p.csv").unwrap_err()
    )
}

#[test]
fn bad_lines_are_named() {
    let h = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n";
    assert!(
        err(&format!("{h}0,0,0,1,0,0,0,1,0,0,0,0,0\n"))
            .contains("p.csv:2: expected 14 values, found 13")
    );
    assert!(err(&format!("{h}0,0,0,1,0,0,0,1,0,0,0,0,0,abc\n")).contains("found 'abc'"));
    assert!(
        err(&format!("{h}0,0,0,-1,0,0,0,1,0,0,0,0,0,0\n")).contains("radius R = -1 must be > 0")
    );
    assert!(err(&format!("{h}0,0,NaN,1,0,0,0,1,0,0,0,0,0,0\n")).contains("finite"));
    assert!(err("x,y,z\n").contains("column 'R' is missing"));
    assert!(err("x,y,z,x\n").contains("appears twice"));
    assert!(err("").contains("empty file"));
}
