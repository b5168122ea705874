//! Runs under `mpirun` (the `mpi` feature; `.ci/run` installs OpenMPI): the output of a run
//! split over 2, 3 and 4 processes is that of one process byte for byte, a checkpoint
//! written on Ctrl-C by 2 processes resumes on 3 with the same bits, and a bad scenario
//! gives one error.
#![cfg(feature = "mpi")]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn mpirun(np: usize, args: &[&str], dir: &Path) -> Command {
    let mut c = Command::new("mpirun");
    c.args(["--oversubscribe", "-np", &np.to_string()])
        .arg(env!("CARGO_BIN_EXE_tinydem"))
        .args(args)
        // Containers run as root; OpenMPI refuses that unless told.
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .current_dir(dir);
    c
}

fn run(np: usize, args: &[&str], dir: &Path) -> Output {
    let out = if np == 1 {
        common::tinydem(args, dir)
    } else {
        mpirun(np, args, dir).output().expect("mpirun runs")
    };
    assert!(
        out.status.success(),
        "{np} processes, {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Resumes the run of scenario `name` in `dir/cut` from its checkpoint on `np` processes.
fn resume(np: usize, name: &str, dir: &Path) {
    let args = [
        "run",
        name,
        "-o",
        "cut",
        "-q",
        "--resume",
        "cut/checkpoint.bin",
    ];
    run(np, &args, dir);
}

/// The files of an output directory that a run writes the same on any process count (all
/// but the checkpoint, which holds the storage order, and run.toml, which names the
/// command line).
fn outputs(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .map(|e| (e.file_name().into_string().unwrap(), e.path()))
        .filter(|(n, _)| n != "checkpoint.bin" && n != "run.toml" && n != ".lock")
        .map(|(n, p)| (n, std::fs::read(p).unwrap()))
        .collect();
    files.sort();
    files
}

/// Runs `scenario` in one process and on each of `counts`: the same files, byte for byte;
/// returns those of one process.
fn same_output(scenario: &Path, counts: &[usize]) -> Vec<(String, Vec<u8>)> {
    let dir = tempfile::tempdir().unwrap();
    let name = scenario.to_str().unwrap();
    run(1, &["run", name, "-o", "one", "-q"], dir.path());
    let one = outputs(&dir.path().join("one"));
    assert!(one.len() > 3, "{name}: {} files", one.len());
    for &np in counts {
        let out = format!("np{np}");
        run(np, &["run", name, "-o", &out, "-q"], dir.path());
        let split = outputs(&dir.path().join(&out));
        let names = |f: &[(String, Vec<u8>)]| f.iter().map(|e| e.0.clone()).collect::<Vec<_>>();
        assert_eq!(
            names(&split),
            names(&one),
            "{name} on {np} processes: other files"
        );
        for ((file, a), (_, b)) in one.iter().zip(&split) {
            assert!(a == b, "{name} on {np} processes: {file} differs");
        }
    }
    one
}

#[test]
fn reference_cases_on_1_to_4_processes_write_the_same_bytes() {
    for case in [
        "headon",
        "oblique_spin",
        "floor_slide",
        "floor_twist",
        "primitives",
        "drag",
        "small_pile",
    ] {
        same_output(
            &common::data(&format!("reference/{case}/scenario.toml")),
            &[2, 3, 4],
        );
    }
}

/// The values of the column `name` of a CSV frame's text, row by row.
fn column<'a>(text: &'a str, name: &str) -> Vec<&'a str> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = header.iter().position(|&h| h == name).expect("the column");
    lines.map(|l| l.split(',').nth(at).unwrap()).collect()
}

/// The filling, discharging silo: spawning, an outlet, wall loads, contact networks in CSV
/// and VTK, each grain's contact force and torque in the frames.
fn silo(dir: &Path, frames: u64) -> PathBuf {
    let path = dir.join("silo.toml");
    std::fs::write(
        &path,
        format!(
            "[geometry]\nradius_min = 0.003\nradius_max = 0.004\nmesh = \"{}\"\nmesh_radii = [0.0]\n\
             spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n\
             [material]\nrestitution = 0.3\nfriction_sliding = 0.5\nfriction_rolling = 0.1\nfriction_twisting = 0.1\n\
             [simulation]\nmax_particles = 300\nframes = {frames}\nsteps_per_frame = 250\n\
             [domain]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, 0.2]\n\
             [[outlets]]\nmin = [-0.1, -0.1, -0.2]\nmax = [0.1, 0.1, -0.05]\n\
             [output]\nwall_forces = true\ncontacts = true\nforces = true\nformats = [\"csv\", \"vtk\"]\n",
            common::data("stages/silo.off").display()
        ),
    )
    .unwrap();
    path
}

#[test]
fn a_filling_silo_on_1_to_4_processes_writes_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    same_output(&silo(dir.path(), 10), &[2, 3, 4]);
}

#[test]
fn a_tumbling_drum_on_1_to_3_processes_writes_the_same_bytes() {
    // A moving mesh, grains crossing between processes in contact all the while.
    let dir = tempfile::tempdir().unwrap();
    let off = common::drum_off(24);
    std::fs::write(dir.path().join("drum.off"), off).unwrap();
    let path = dir.path().join("drum.toml");
    std::fs::write(
        &path,
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\n\
         spawn_min = [-0.035, -0.01, -0.035]\nspawn_max = [0.035, 0.01, 0.035]\n\
         [material]\nyoungs_modulus = 1e6\nrestitution = 0.3\nfriction_sliding = 0.6\nfriction_rolling = 0.1\nfriction_twisting = 0.1\n\
         [simulation]\nmax_particles = 120\nframes = 12\nsteps_per_frame = 500\n\
         [[meshes]]\nfile = \"drum.off\"\nradii = [0.0]\n\
         motion = { type = \"rotation\", center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], angular_velocity = 30.0 }\n\
         [output]\nwall_forces = true\nformats = [\"csv\", \"vtk\"]\n",
    )
    .unwrap();
    same_output(&path, &[2, 3]);
}

/// A bed falling onto a floor of fixed grains (`[[fixed]]`): the flags go to the processes
/// that own the grains, and the frames carry them, the same on any process count.
#[test]
fn a_fixed_floor_on_1_to_3_processes_writes_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz\n");
    for k in 0..200 {
        let (i, j, l) = (k % 10, (k / 10) % 10, k / 100);
        let z = if l == 0 {
            0.0
        } else {
            0.012 + 0.002 * (k % 3) as f64
        };
        let x = 0.01 * (i as f64 - 4.5) + if l == 0 { 0.0 } else { 0.003 };
        let y = 0.01 * (j as f64 - 4.5);
        csv += &format!("{x},{y},{z},0.005,0,0,0,1,0,0,0,0,0,0\n");
    }
    std::fs::write(dir.path().join("bed.csv"), csv).unwrap();
    let path = dir.path().join("bed.toml");
    std::fs::write(
        &path,
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\nmesh_radii = [0.0]\n\
         [material]\nyoungs_modulus = 1e6\nrestitution = 0.3\n\
         [simulation]\nmax_particles = 0\nspawn_attempts = 0\nframes = 6\nsteps_per_frame = 400\n\
         [[fixed]]\nmin = [-1.0, -1.0, -0.001]\nmax = [1.0, 1.0, 0.001]\n\
         [input]\nparticles = \"bed.csv\"\n",
    )
    .unwrap();
    same_output(&path, &[2, 3]);
    run(
        2,
        &["run", path.to_str().unwrap(), "-o", "two", "-q"],
        dir.path(),
    );
    let last = std::fs::read_to_string(dir.path().join("two/particles000006.csv")).unwrap();
    assert!(last.starts_with("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,fixed\n"));
    let fixed = last.lines().filter(|l| l.ends_with(",1")).count();
    assert_eq!(fixed, 100);
}

/// `[simulation] until`: a pour into a box that ends when it is still, and a silo that ends
/// when its outlet has taken 20 grains, end at the same frame with the same bytes on any
/// process count.
#[test]
fn runs_ended_by_until_on_1_to_3_processes_write_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("box.off"),
        "OFF\n8 5 0\n-0.03 -0.03 0\n0.03 -0.03 0\n0.03 0.03 0\n-0.03 0.03 0\n\
         -0.03 -0.03 0.2\n0.03 -0.03 0.2\n0.03 0.03 0.2\n-0.03 0.03 0.2\n\
         4 0 1 2 3\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
    )
    .unwrap();
    let pour = dir.path().join("pour.toml");
    std::fs::write(
        &pour,
        "[geometry]\nradius_min = 0.004\nradius_max = 0.005\nmesh = \"box.off\"\nmesh_radii = [0.0]\n\
         [simulation]\nframes = 100\nsteps_per_frame = 1000\n\
         until = { kinetic_energy_below = 1e-7 }\n\
         [[spawn]]\nmin = [-0.025, -0.025, 0.02]\nmax = [0.025, 0.025, 0.1]\ncount = 60\n",
    )
    .unwrap();
    same_output(&pour, &[2, 3]);
    let silo = silo(dir.path(), 400);
    let text = std::fs::read_to_string(&silo).unwrap();
    let text = text.replace(
        "steps_per_frame = 250\n",
        "steps_per_frame = 250\nuntil = { removed_at_least = 20 }\n",
    );
    std::fs::write(&silo, text).unwrap();
    same_output(&silo, &[2, 3]);
    let name = silo.to_str().unwrap();
    run(1, &["run", name, "-o", "ended", "-q"], dir.path());
    let log = std::fs::read_to_string(dir.path().join("ended/log.csv")).unwrap();
    let last = log.lines().last().unwrap();
    assert!(last.ends_with(",removed_at_least"), "{last}");
    assert!(log.lines().count() < 402, "not ended early");
}

/// A servo lid pressing grains poured into a periodic cell (built-in planes): the same
/// bytes (frames, `log.csv` with the lid's position and load, `walls.csv`) on any process
/// count.
#[test]
fn a_servo_lid_on_1_to_3_processes_writes_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let cell = dir.path().join("cell.toml");
    std::fs::write(
        &cell,
        "[geometry]\nradius_min = 0.003\nradius_max = 0.004\n\
         spawn_min = [-0.03, -0.03, 0.005]\nspawn_max = [0.03, 0.03, 0.05]\n\
         [simulation]\nmax_particles = 250\nframes = 6\nsteps_per_frame = 300\n\
         [domain]\nmin = [-0.03, -0.03, -0.01]\nmax = [0.03, 0.03, 0.1]\nperiodic = [true, true, false]\n\
         [output]\nwall_forces = true\nforces = true\n\
         [[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.4 }\n\
         [[meshes]]\nshape = { type = \"plane\", point = [0.0, 0.0, 0.06], normal = [0.0, 0.0, 1.0], size = 0.4 }\n\
         motion = { type = \"servo\", direction = [0.0, 0.0, -1.0], stress = 150.0, max_speed = 0.5 }\n",
    )
    .unwrap();
    same_output(&cell, &[2, 3]);
}

#[test]
fn ctrl_c_on_2_processes_checkpoints_and_3_resume_with_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = silo(dir.path(), 600);
    let name = scenario.to_str().unwrap();
    run(1, &["run", name, "-o", "one", "-q"], dir.path());
    let child = mpirun(2, &["run", name, "-o", "cut", "-q"], dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Interrupted once some frames are out.
    let frames = dir.path().join("cut/frames.csv");
    let start = Instant::now();
    while std::fs::read_to_string(&frames).map_or(0, |t| t.lines().count()) < 30 {
        assert!(start.elapsed() < Duration::from_secs(60), "no frames");
        std::thread::sleep(Duration::from_millis(20));
    }
    // SIGINT to mpirun, which passes it on to the processes.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let out = child.wait_with_output().unwrap();
    assert!(!out.status.success(), "the run should stop interrupted");
    // Said once, by the first process, before any process exits.
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("interrupted after step").count(), 1, "{err}");
    let cut = dir.path().join("cut");
    assert!(cut.join("checkpoint.bin").exists() && cut.join("interrupted.csv").exists());
    let done = std::fs::read_to_string(&frames).unwrap().lines().count();
    assert!(
        done < 600,
        "interrupted after {done} frames: too late to tell"
    );
    resume(3, name, dir.path());
    let (one, resumed) = (outputs(&dir.path().join("one")), outputs(&cut));
    for (file, a) in &one {
        let b = resumed.iter().find(|e| &e.0 == file).map(|e| &e.1);
        assert!(b == Some(a), "{file} differs after resuming on 3 processes");
    }
}

#[test]
fn a_panic_on_one_process_ends_the_job_instead_of_leaving_the_others_waiting() {
    // Process 1 panics at the start; the others wait in the run's first collective. MPI_Abort
    // from the panic hook ends them all, with the message.
    let dir = tempfile::tempdir().unwrap();
    let path = silo(dir.path(), 2);
    let mut child = mpirun(
        3,
        &["run", path.to_str().unwrap(), "-o", "out", "-q"],
        dir.path(),
    )
    .env("TINYDEM_TEST_PANIC_RANK", "1")
    .stderr(std::process::Stdio::piped())
    .spawn()
    .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("the other processes still wait after 60 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("a panic on process 1 for the test"), "{err}");
}

#[test]
fn a_bad_scenario_on_3_processes_gives_one_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[geometry]\nradius_min = -1\n").unwrap();
    let start = Instant::now();
    let out = mpirun(3, &["run", "bad.toml", "-o", "out"], dir.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "it should not hang"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("error: ").count(), 1, "{err}");
    assert!(err.contains("radius_min = -1"), "{err}");
}

#[test]
fn clumps_in_a_filling_silo_on_1_to_3_processes_write_the_same_bytes() {
    // The silo filled with dimers and triangles beside spheres: frames with the clump
    // column, every sphere in VTK with its body, contacts, removal of whole clumps.
    let dir = tempfile::tempdir().unwrap();
    let path = silo(dir.path(), 8);
    let spheres = "spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n";
    let region = "[[spawn]]\nmin = [-0.05, -0.05, 0.06]\nmax = [0.05, 0.05, 0.14]\n";
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(spheres, "")
        .replace("max_particles = 300", "max_particles = 500")
        + "[[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.005, 0.0, 0.0, 0.0035]]\n\
           [[clumps]]\nname = \"tri\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.006, 0.0, 0.0, 0.0035], [0.003, 0.0052, 0.0, 0.0035]]\n"
        + &format!(
            "{region}clump = \"dimer\"\ncount = 70\n{region}clump = \"tri\"\ncount = 50\n{region}count = 60\n"
        );
    std::fs::write(&path, text).unwrap();
    let files = same_output(&path, &[2, 3]);
    let last = files
        .iter()
        .rfind(|f| f.0.starts_with("particles") && f.0.ends_with(".csv"))
        .unwrap();
    let last = String::from_utf8_lossy(&last.1);
    let clumps = column(&last, "clump");
    let count = |c: &str| clumps.iter().filter(|&&k| k == c).count();
    assert!(
        count("0") > 30 && count("1") > 20 && count("-1") > 30,
        "{clumps:?}"
    );
}

#[test]
fn frames_in_pieces_on_2_and_3_processes_are_the_gathered_frames() {
    // `gather = "never"`: each process writes its piece of every frame and contact network
    // (CSV and VTK), the first the .pvtu/.pvtp that list them; joined, they are the frames
    // of the run in one process (tests/pieces_check.py reads the VTK with meshio).
    if !common::has_meshio() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = silo(dir.path(), 6);
    let text = std::fs::read_to_string(&path).unwrap() + "gather = \"never\"\n";
    std::fs::write(&path, text).unwrap();
    let name = path.to_str().unwrap();
    run(1, &["run", name, "-o", "one", "-q"], dir.path());
    for np in [2, 3] {
        let out = format!("np{np}");
        run(np, &["run", name, "-o", &out, "-q"], dir.path());
        let check = Command::new("python3")
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/pieces_check.py"))
            .args(["one", &out, "6"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(
            check.status.success(),
            "{np} processes: {}{}",
            String::from_utf8_lossy(&check.stdout),
            String::from_utf8_lossy(&check.stderr)
        );
        let pieces = std::fs::read_dir(dir.path().join(&out))
            .unwrap()
            .filter(|e| {
                let name = e.as_ref().unwrap().file_name();
                name.to_string_lossy().starts_with("particles000006_")
            })
            .count();
        assert_eq!(pieces, 2 * np, "a CSV and a VTK piece per process");
        // analyze and render read the pieces as the gathered frames.
        for args in [
            vec!["analyze", "DIR", "--csv", "DIR/a.csv"],
            vec!["render", "DIR/particles000006.csv"],
        ] {
            for d in ["one", out.as_str()] {
                let a: Vec<String> = args.iter().map(|a| a.replace("DIR", d)).collect();
                let a: Vec<&str> = a.iter().map(String::as_str).collect();
                run(1, &a, dir.path());
            }
        }
        let same = |file: &str| {
            let read = |d: &str| std::fs::read(dir.path().join(d).join(file)).unwrap();
            assert!(read("one") == read(&out), "{np} processes: {file} differs");
        };
        same("a.csv");
        same("particles000006.png");
        // The checkpoint is in parts, one per process, and is the run's state: a stage
        // from it (in one process) writes what a stage from the gathered one does.
        let files: Vec<String> = std::fs::read_dir(dir.path().join(&out))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with("checkpoint"))
            .collect();
        assert_eq!(files.len(), np, "{np} processes: {files:?}");
        assert!(files.iter().all(|f| f.contains(&format!("-of-{np}"))));
        for from in ["one", out.as_str()] {
            let (checkpoint, to) = (format!("{from}/checkpoint.bin"), format!("from_{from}"));
            let args = [
                "run",
                name,
                "--from",
                &checkpoint,
                "-o",
                &to,
                "-q",
                "--overwrite",
            ];
            run(1, &args, dir.path());
        }
        let from_one = outputs(&dir.path().join("from_one"));
        assert!(from_one == outputs(&dir.path().join(format!("from_{out}"))));
    }
}

/// The filling silo of 10 frames (its path), run to frame 6 in pieces on 3 processes into
/// `dir/cut`: its checkpoint is in 3 parts. Returns the scenarios of 10 and 6 frames.
fn silo_in_parts(dir: &Path) -> (PathBuf, PathBuf) {
    let path = silo(dir, 10);
    let text = std::fs::read_to_string(&path).unwrap();
    let short = dir.join("short.toml");
    let in_pieces = text.replace("frames = 10", "frames = 6") + "gather = \"never\"\n";
    std::fs::write(&short, in_pieces).unwrap();
    run(3, &["run", short.to_str().unwrap(), "-o", "cut", "-q"], dir);
    let names = file_names(&dir.join("cut"));
    let parts = names.iter().filter(|n| n.contains(".part-")).count();
    assert_eq!(parts, 3, "the checkpoint in a part per process");
    (path, short)
}

/// The names of the files in `dir`.
fn file_names(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect()
}

/// A copy of the directory `dir/from` at `dir/to`.
fn copy_dir(dir: &Path, from: &str, to: &str) {
    std::fs::create_dir(dir.join(to)).unwrap();
    for name in file_names(&dir.join(from)) {
        std::fs::copy(dir.join(from).join(&name), dir.join(to).join(&name)).unwrap();
    }
}

#[test]
fn a_checkpoint_in_parts_of_3_processes_resumes_in_shares_on_4_2_and_1_with_the_same_bytes() {
    // A run in pieces on 3 processes ends with its checkpoint in 3 parts; extended to more
    // frames on 4 processes (the first reads no part, the others one each: no process
    // reads all), on 2 and in one, the new frames are those of the run never cut. On 4,
    // every collective goes in rounds of a few kB (MPI's 32-bit counts for big messages).
    let dir = tempfile::tempdir().unwrap();
    let (path, _) = silo_in_parts(dir.path());
    let name = path.to_str().unwrap();
    run(1, &["run", name, "-o", "one", "-q"], dir.path());
    // And the parts joined into one file by `tinydem checkpoint merge`, resumed in one.
    copy_dir(dir.path(), "cut", "merged");
    run(
        1,
        &["checkpoint", "merge", "merged/checkpoint.bin"],
        dir.path(),
    );
    assert!(dir.path().join("merged/checkpoint.bin").exists());
    for (out, np) in [
        ("resumed4", 4),
        ("resumed2", 2),
        ("resumed1", 1),
        ("merged", 1),
    ] {
        if out != "merged" {
            copy_dir(dir.path(), "cut", out);
        }
        let checkpoint = format!("{out}/checkpoint.bin");
        let args = ["run", name, "-o", out, "-q", "--resume", &checkpoint];
        let resumed = match np {
            1 => common::tinydem(&args, dir.path()),
            _ => {
                let mut c = mpirun(np, &args, dir.path());
                if np == 4 {
                    c.env("TINYDEM_MPI_ROUND_BYTES", "4000");
                }
                c.output().unwrap()
            }
        };
        assert!(
            resumed.status.success(),
            "{np}: {}",
            String::from_utf8_lossy(&resumed.stderr)
        );
        for k in 7..=10 {
            for file in [
                format!("particles{k:06}.csv"),
                format!("contacts{k:06}.csv"),
            ] {
                let read = |d: &str| std::fs::read(dir.path().join(d).join(&file)).unwrap();
                assert!(read("one") == read(out), "{out}: {file} differs");
            }
        }
        // The collection lists each frame's file: the pieces' listings, then whole files.
        let pvd = std::fs::read_to_string(dir.path().join(out).join("particles.pvd")).unwrap();
        let files: Vec<&str> = (pvd.split("file=\"").skip(1))
            .map(|t| &t[..t.find('"').unwrap()])
            .collect();
        let expected: Vec<String> = (0..=10)
            .map(|k| format!("particles{k:06}.{}", if k <= 6 { "pvtu" } else { "vtu" }))
            .collect();
        assert_eq!(files, expected, "{out}");
    }
}

#[test]
fn parts_of_two_runs_mixed_are_refused_on_any_process_count() {
    // Another run's part 0, of the same step (the same silo with its grains tagged): on 3
    // processes that each read one part, and in one that reads all.
    let dir = tempfile::tempdir().unwrap();
    let (path, short) = silo_in_parts(dir.path());
    let tagged = dir.path().join("tagged.toml");
    let other = std::fs::read_to_string(&short).unwrap()
        + "[[tags]]\nmin = [-1.0, -1.0, -1.0]\nmax = [0.0, 1.0, 1.0]\ntag = 3\n";
    std::fs::write(&tagged, other).unwrap();
    run(
        3,
        &["run", tagged.to_str().unwrap(), "-o", "other", "-q"],
        dir.path(),
    );
    copy_dir(dir.path(), "cut", "mixed");
    let names = file_names(&dir.path().join("other"));
    let part0 = names.iter().find(|n| n.contains(".part-0-of-3")).unwrap();
    let from = dir.path().join("other").join(part0);
    std::fs::copy(from, dir.path().join("mixed").join(part0)).unwrap();
    let name = path.to_str().unwrap();
    let args = [
        "run",
        name,
        "-o",
        "mixed",
        "-q",
        "--resume",
        "mixed/checkpoint.bin",
    ];
    for (np, says) in [(3, "not of one state"), (1, "not of the state of part 0")] {
        let out = match np {
            1 => common::tinydem(&args, dir.path()),
            _ => mpirun(np, &args, dir.path()).output().unwrap(),
        };
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{np}: mixed parts resumed");
        assert!(err.contains(says), "{np}: {err}");
    }
}

#[test]
fn a_particle_file_of_clumps_without_ids_read_in_shares_writes_the_same_bytes() {
    // Each process reads its share of the file (none reads it all): rows without ids, so a
    // row's id is its place in the file, after the spheres of the clumps before it.
    let dir = tempfile::tempdir().unwrap();
    let path = silo(dir.path(), 4);
    let mut rows = String::from("x,y,z,R,vx,vy,vz,q0,q1,q2,q3,wx,wy,wz,clump\n");
    for k in 0..120 {
        let (x, y, z) = (
            (k % 6) as f64 * 0.015 - 0.04,
            (k / 6 % 5) as f64 * 0.015 - 0.03,
            0.07 + (k / 30) as f64 * 0.015,
        );
        let clump = [0, -1, 1][k % 3];
        let r = [0.006, 0.0035, 0.0065][k % 3];
        rows += &format!("{x},{y},{z},{r},0,0,-0.5,1,0,0,0,0,0,0,{clump}\n");
    }
    std::fs::write(dir.path().join("grains.csv"), rows).unwrap();
    let spheres = "spawn_min = [-0.05, -0.05, 0.06]\nspawn_max = [0.05, 0.05, 0.14]\n";
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(spheres, "")
        .replace("max_particles = 300", "max_particles = 0")
        + "[input]\nparticles = \"grains.csv\"\n\
           [[clumps]]\nname = \"dimer\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.005, 0.0, 0.0, 0.0035]]\n\
           [[clumps]]\nname = \"tri\"\nspheres = [[0.0, 0.0, 0.0, 0.0035], [0.006, 0.0, 0.0, 0.0035], [0.003, 0.0052, 0.0, 0.0035]]\n";
    std::fs::write(&path, text).unwrap();
    let files = same_output(&path, &[2, 3, 4]);
    let first = &files
        .iter()
        .find(|f| f.0 == "particles000000.csv")
        .unwrap()
        .1;
    // Rows: dimer (ids 0, 1), sphere (2), triangle (3, 4, 5), dimer (6, 7), ...
    let text = String::from_utf8_lossy(first);
    let ids = &column(&text, "id")[..4];
    assert_eq!(
        ids,
        ["0", "2", "3", "6"],
        "a row's id follows the spheres before it"
    );
}

#[test]
fn a_sheared_periodic_box_on_1_to_3_processes_writes_the_same_bytes() {
    // The shear cell of the examples (periodic along x, y and z, Lees-Edwards boundaries,
    // two materials, contact networks), for fewer frames.
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/h_shear_cell");
    let text = std::fs::read_to_string(example.join("scenario.toml"))
        .unwrap()
        .replace("frames = 40", "frames = 6")
        .replace(
            "particles = \"initial.csv\"",
            &format!("particles = \"{}\"", example.join("initial.csv").display()),
        );
    assert!(text.contains("frames = 6") && text.contains("lees_edwards"));
    let path = dir.path().join("shear.toml");
    std::fs::write(&path, text).unwrap();
    same_output(&path, &[2, 3]);
}

#[test]
fn commands_that_do_not_step_run_once_under_mpirun() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = silo(dir.path(), 4);
    let name = scenario.to_str().unwrap();
    let one = run(1, &["check", name], dir.path());
    let two = run(2, &["check", name], dir.path());
    let (one, two) = (
        String::from_utf8_lossy(&one.stdout),
        String::from_utf8_lossy(&two.stdout),
    );
    // The same report, once (but the free space and the threads it would run on).
    assert_eq!(two.matches("scenario is valid").count(), 1, "{two}");
    assert_eq!(two.lines().count(), one.lines().count(), "{two}");
}

/// A settled bed of 10^6 grains (the benchmark's 10^5 packing, 5 x 2 tiles) in an open box,
/// for `frames` frames of `steps` steps: its checkpoint is 300 MB, 3-5 s to gather and
/// write on the 2-core CI machine.
fn million(dir: &Path, frames: u64, steps: u64) -> PathBuf {
    use std::io::{BufRead, Write};
    let bench = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/data/n100000");
    let edge: f64 = std::fs::read_to_string(bench.join("edge.txt"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let gz =
        flate2::read::GzDecoder::new(std::fs::File::open(bench.join("settled.csv.gz")).unwrap());
    let lines: Vec<String> = std::io::BufReader::new(gz)
        .lines()
        .map(|l| l.unwrap())
        .collect();
    let mut csv = std::io::BufWriter::new(std::fs::File::create(dir.join("bed.csv")).unwrap());
    writeln!(csv, "{}", lines[0]).unwrap();
    for (ix, iy) in (0..5).flat_map(|ix| (0..2).map(move |iy| (ix, iy))) {
        for line in &lines[1..] {
            let (x, rest) = line.split_once(',').unwrap();
            let (y, rest) = rest.split_once(',').unwrap();
            let x: f64 = x.parse::<f64>().unwrap() + ix as f64 * edge;
            let y: f64 = y.parse::<f64>().unwrap() + iy as f64 * edge;
            writeln!(csv, "{x:?},{y:?},{rest}").unwrap();
        }
    }
    csv.into_inner().unwrap().sync_all().unwrap();
    let (lx, ly, lz) = (5.0 * edge, 2.0 * edge, edge);
    std::fs::write(
        dir.join("box.off"),
        format!(
            "OFF\n8 5 0\n0 0 0\n{lx} 0 0\n{lx} {ly} 0\n0 {ly} 0\n0 0 {lz}\n{lx} 0 {lz}\n{lx} {ly} {lz}\n0 {ly} {lz}\n\
             4 0 1 2 3\n4 0 3 7 4\n4 1 2 6 5\n4 0 1 5 4\n4 3 2 6 7\n"
        ),
    )
    .unwrap();
    let path = dir.join("bed.toml");
    std::fs::write(
        &path,
        format!(
            "[geometry]\nradius_min = 0.004\nradius_max = 0.005\nmesh = \"box.off\"\nmesh_radii = [0.0]\n\
             [material]\nyoungs_modulus = 1e6\nrestitution = 0.5\nfriction_sliding = 0.3\nfriction_rolling = 0.3\n\
             [simulation]\nmax_particles = 0\nspawn_attempts = 0\nframes = {frames}\nsteps_per_frame = {steps}\n\
             [input]\nparticles = \"bed.csv\"\n"
        ),
    )
    .unwrap();
    path
}

/// The lines of `dir/frames.csv` (0 while it is not there).
fn frames_out(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("frames.csv")).map_or(0, |t| t.lines().count())
}

/// Starts the run of scenario `name` on 2 processes into `dir/cut`, its stderr piped, and
/// waits until its `frames.csv` has `lines` lines.
fn start_cut(name: &str, dir: &Path, lines: usize) -> (std::process::Child, PathBuf) {
    let child = mpirun(2, &["run", name, "-o", "cut", "-q"], dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let cut = dir.join("cut");
    wait_for_frames(&cut, lines);
    (child, cut)
}

/// Waits until `dir/frames.csv` has `lines` lines.
fn wait_for_frames(dir: &Path, lines: usize) {
    let start = Instant::now();
    while frames_out(dir) < lines {
        assert!(start.elapsed() < Duration::from_secs(120), "no frames");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn sigterm_to_mpirun_keeps_a_checkpoint_that_takes_seconds_to_gather() {
    // mpirun answers SIGTERM with SIGCONT to the processes, SIGTERM a second later and
    // SIGKILL a second after that: far less than the gathered checkpoint of 10^6 grains
    // takes. The processes write their parts of it at once on SIGCONT and keep them when
    // SIGTERM comes (in the same step, or a few steps later: a new checkpoint might not be
    // complete before SIGKILL), and the parts resume exactly (here in one process).
    let dir = tempfile::tempdir().unwrap();
    let scenario = million(dir.path(), 2, 20);
    let name = scenario.to_str().unwrap();
    let (child, cut) = start_cut(name, dir.path(), 2);
    std::thread::sleep(Duration::from_millis(1500));
    let asked = Instant::now();
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let out = child.wait_with_output().unwrap();
    let ended = asked.elapsed();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(ended < Duration::from_secs(5), "mpirun took {ended:?}");
    // The parts written on SIGCONT are what must survive; with both cores busy the
    // processes may be killed before they report SIGTERM (seen on a loaded machine), and
    // the resume below shows that the parts suffice.
    let reported = err.matches("interrupted after step").count();
    assert!(
        reported == 1 || (reported == 0 && err.contains("SIGCONT: checkpoint of step")),
        "{err}"
    );
    assert!(frames_out(&cut) < 4, "stopped after the run: {err}");
    resume(1, name, dir.path());
    run(1, &["run", name, "-o", "whole", "-q"], dir.path());
    for file in ["particles000002.csv", "log.csv"] {
        let a = std::fs::read(dir.path().join("whole").join(file)).unwrap();
        let b = std::fs::read(cut.join(file)).unwrap();
        assert!(a == b, "{file} differs after the stop and resume");
    }
}

#[test]
fn sigusr1_to_mpirun_stops_the_run_with_a_checkpoint_and_exit_130() {
    // mpirun passes SIGUSR1 on and waits: the way to stop a split run with no deadline.
    let dir = tempfile::tempdir().unwrap();
    let scenario = silo(dir.path(), 600);
    let name = scenario.to_str().unwrap();
    let (child, cut) = start_cut(name, dir.path(), 20);
    unsafe { libc::kill(child.id() as i32, libc::SIGUSR1) };
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert_eq!(err.matches("interrupted after step").count(), 1, "{err}");
    // The parts were joined into the one file, and the run resumes from it.
    let names: Vec<String> = std::fs::read_dir(&cut)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| !n.contains(".part-")), "{names:?}");
    assert!(
        names.iter().any(|n| n == "checkpoint.bin") && names.iter().any(|n| n == "interrupted.csv")
    );
    resume(3, name, dir.path());
    assert_eq!(frames_out(&cut), 602);
}
