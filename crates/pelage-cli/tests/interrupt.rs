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
