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

/// The optional field the tests have (`probe`) is a column of the frames: written after the
/// others, read back with the same bits; a frame without it has no such column.
#[test]
fn an_optional_field_is_a_column_read_back_exactly() {
    let mut p: Particles = (0..3)
        .map(|k| Particle {
            x: DVec3::new(k as f64, 0.0, 0.0),
            radius: 0.004,
            ..Default::default()
        })
        .collect();
    let mut plain = Vec::new();
    write_particles(&mut plain, &p, Extra::default()).unwrap();
    assert!(!String::from_utf8_lossy(&plain).contains("probe"));
    assert!(p.activate("probe"));
    p.probe = vec![1.0 / 3.0, -1e-300, 7.0];
    let mut text = Vec::new();
    write_particles(&mut text, &p, Extra::default()).unwrap();
    let header = String::from_utf8_lossy(&text)
        .lines()
        .next()
        .unwrap()
        .to_string();
    assert!(header.ends_with(",probe"), "{header}");
    let back = read_particles(&text[..], "frame.csv").unwrap();
    assert!(back.active.probe);
    let bits = |v: &[f64]| v.iter().map(|s| s.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.probe), bits(&p.probe));
}

#[test]
fn a_frame_missing_part_of_a_field_or_with_a_bad_value_is_refused() {
    let header = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,probe\n";
    let ok = format!("{header}0,0,0,1,0,0,0,1,0,0,0,0,0,0,2.5\n");
    let p = read_particles(ok.as_bytes(), "f.csv").unwrap();
    assert_eq!(p.probe, vec![2.5]);
    let bad = format!("{header}0,0,0,1,0,0,0,1,0,0,0,0,0,0,nan\n");
    let e = read_particles(bad.as_bytes(), "f.csv").unwrap_err();
    assert!(format!("{e:#}").contains("f.csv:2: probe"), "{e:#}");
    let twice = "x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,probe,probe\n";
    let e = read_particles(twice.as_bytes(), "f.csv").unwrap_err();
    assert!(format!("{e:#}").contains("'probe' appears twice"), "{e:#}");
}
