//! Interrupted writes: a long `pelage groom` is killed at random moments,
//! with SIGKILL (nothing can clean up) and with SIGINT (Ctrl-C: pelage
//! removes its temporary files and exits with 130). After every trial the
//! destination is either absent or the complete file of an earlier run,
//! byte for byte; after SIGINT no temporary file is left; and the next run
//! that writes the same file removes what SIGKILL left behind.

#![cfg(unix)]

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Enough hairs that the debug binary writes for a second or more.
const GROOM: &str = "[mesh]\npath = \"spot\"\n[roots]\ncount = 60000\nparts = 24\n[guides]\ngenerate = { count = 100, length = 0.05 }\n[[ops]]\nnoise = { amplitude = 0.002, frequency = 20 }\n[finish]\npoints = 12\n[output]\npath = \"out.usdc\"\n";

fn groom(dir: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_pelage"));
    command
        .args(["groom", "g.toml", "-q"])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    command
}

fn temporary_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect()
}

/// The tests time their signals against a whole run's length: they run
/// one at a time, so neither slows the other's runs.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A deterministic spread of moments over `0..span`.
fn moment(trial: u64, span: Duration) -> Duration {
    let mut x = trial.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    span.mul_f64((x % 10_000) as f64 / 10_000.0)
}

#[test]
fn killed_and_interrupted_grooms_leave_the_destination_whole() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("g.toml"), GROOM).unwrap();
    let out = dir.path().join("out.usdc");

    // The complete file, and how long writing it takes.
    let started = Instant::now();
    let status = groom(dir.path()).status().unwrap();
    let full = started.elapsed();
    assert!(status.success());
    let complete = std::fs::read(&out).unwrap();
    eprintln!(
        "a whole run takes {:.2} s and writes {} bytes",
        full.as_secs_f64(),
        complete.len()
    );

    let (mut killed_mid_write, mut debris_seen) = (0, 0);
    for (signal, name) in [(libc::SIGKILL, "SIGKILL"), (libc::SIGINT, "SIGINT")] {
        for trial in 0..20u64 {
            // The first trials of each signal start with no destination.
            let fresh = trial < 4;
            if fresh {
                std::fs::remove_file(&out).unwrap();
            }
            let child = groom(dir.path()).spawn().unwrap();
            std::thread::sleep(moment(trial + 100 * signal as u64, full));
            let pid = child.id() as libc::pid_t;
            // SAFETY: sending a signal to our own child.
            unsafe { libc::kill(pid, signal) };
            let output = child.wait_with_output().unwrap();
            let stderr = String::from_utf8_lossy(&output.stderr);
            let finished = output.status.success();
            match std::fs::read(&out) {
                Ok(bytes) => assert!(
                    bytes == complete,
                    "{name} trial {trial}: the destination is not the complete file ({} bytes)",
                    bytes.len()
                ),
                Err(_) => assert!(
                    fresh && !finished,
                    "{name} trial {trial}: the destination vanished"
                ),
            }
            let debris = temporary_files(dir.path());
            if !finished {
                killed_mid_write += usize::from(!debris.is_empty() || signal == libc::SIGINT);
            }
            if signal == libc::SIGINT {
                assert!(
                    debris.is_empty(),
                    "SIGINT trial {trial}: left {debris:?} ({stderr})"
                );
                assert!(
                    finished || output.status.code() == Some(130),
                    "SIGINT trial {trial}: {} ({stderr})",
                    output.status
                );
            } else if !debris.is_empty() {
                debris_seen += 1;
                // The next write of the same file removes it.
                assert!(groom(dir.path()).status().unwrap().success());
                assert_eq!(
                    temporary_files(dir.path()),
                    Vec::<String>::new(),
                    "SIGKILL trial {trial}: the next run left the debris"
                );
                assert!(std::fs::read(&out).unwrap() == complete);
            }
            if !out.exists() {
                assert!(groom(dir.path()).status().unwrap().success());
            }
        }
    }
    eprintln!(
        "40 trials: {killed_mid_write} interrupted before the end, SIGKILL left debris {debris_seen} times, each removed by the next run"
    );
    assert!(
        killed_mid_write >= 20,
        "only {killed_mid_write} trials interrupted the run: the moments miss it"
    );
}

/// A `--frame-files` cache of 40 frames over seed 1, then rewritten over
/// seed 2, interrupted early and late: the stitching layer never stitches
/// frames of two runs (it is there only beside one run's frames), and
/// after SIGINT no temporary file is left, however early it comes.
#[test]
fn an_interrupted_frame_cache_never_stitches_two_runs() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let frames = 40;
    let text = |seed: u32| {
        format!(
            "[mesh]\npath = \"spot\"\n[roots]\ncount = 3000\nseed = {seed}\n[guides]\ngenerate = {{ count = 20, length = 0.05 }}\n[animation]\nframes = \"1-{frames}\"\n"
        )
    };
    let run = |dir: &Path| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_pelage"));
        command
            .args(["groom", "g.toml", "-q", "-o", "out.usda", "--frame-files"])
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        command
    };
    let frame = |dir: &Path, f: u32| std::fs::read(dir.join(format!("out.f{f:04}.usdc"))).ok();
    // Each run's frames, whole.
    let whole = |seed| {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("g.toml"), text(seed)).unwrap();
        let started = Instant::now();
        assert!(run(dir.path()).status().unwrap().success());
        let took = started.elapsed();
        let files: Vec<Vec<u8>> = (1..=frames)
            .map(|f| frame(dir.path(), f).unwrap())
            .collect();
        (dir, files, took)
    };
    let (old_dir, old, _) = whole(1);
    let (_, new, full) = whole(2);
    assert!(old != new, "the two seeds write different frames");
    eprintln!("a whole cache takes {:.2} s", full.as_secs_f64());

    for trial in 0..16u64 {
        let signal = if trial % 4 == 3 {
            libc::SIGKILL
        } else {
            libc::SIGINT
        };
        // Each trial starts from the first run's complete cache.
        let dir = tempfile::tempdir().unwrap();
        for entry in std::fs::read_dir(old_dir.path()).unwrap() {
            let entry = entry.unwrap();
            std::fs::copy(entry.path(), dir.path().join(entry.file_name())).unwrap();
        }
        std::fs::write(dir.path().join("g.toml"), text(2)).unwrap();
        let child = run(dir.path()).spawn().unwrap();
        // Half the trials in the first tenth of the run (temporary files
        // being created as the signal lands), half anywhere.
        let span = if trial % 2 == 0 { full / 10 } else { full };
        std::thread::sleep(moment(trial + 7, span));
        // SAFETY: sending a signal to our own child.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        if dir.path().join("out.usda").exists() {
            let now: Vec<Option<Vec<u8>>> = (1..=frames).map(|f| frame(dir.path(), f)).collect();
            let one_run = now.iter().zip(&old).all(|(n, o)| n.as_ref() == Some(o))
                || now.iter().zip(&new).all(|(n, w)| n.as_ref() == Some(w));
            assert!(
                one_run,
                "trial {trial}: the stitching layer is beside frames of two runs ({stderr})"
            );
        }
        if signal == libc::SIGINT {
            let debris = temporary_files(dir.path());
            assert!(
                debris.is_empty(),
                "SIGINT trial {trial}: left {debris:?} ({stderr})"
            );
        }
    }
}
