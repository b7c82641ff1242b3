//! The hostile-input suite: every case of `tests/hostile/cases.toml` runs
//! the `pelage` binary in a fresh folder under an 8 GB address-space limit
//! and a 60 s time-out, and must end as the case says: no panic, no abort,
//! no time-out, no temporary file left behind, the right exit code, the
//! message naming file and place. See the manifest's head for the fields.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    case: Vec<Case>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    name: String,
    args: Vec<String>,
    #[serde(default)]
    files: Vec<String>,
    #[serde(default)]
    write: BTreeMap<String, String>,
    exit: Exit,
    #[serde(default)]
    stderr: Vec<String>,
    #[serde(default)]
    stdout: Vec<String>,
    #[serde(default)]
    unchanged: Vec<String>,
    #[serde(default)]
    absent: Vec<String>,
    #[serde(default)]
    present: Vec<String>,
    #[serde(default)]
    not_blank: Vec<String>,
    #[serde(default)]
    allow_temporary: Vec<String>,
    /// Text files and pieces each must contain.
    #[serde(default)]
    contains: BTreeMap<String, Vec<String>>,
    /// The longest stderr allowed, in bytes.
    #[serde(default)]
    stderr_at_most: Option<usize>,
    /// Files that a second run of the command writes byte for byte the
    /// same.
    #[serde(default)]
    reproducible: Vec<String>,
    #[serde(default)]
    gpu: bool,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Exit {
    One(i32),
    Any(Vec<i32>),
}

impl Exit {
    fn admits(&self, code: i32) -> bool {
        match self {
            Exit::One(c) => *c == code,
            Exit::Any(codes) => codes.contains(&code),
        }
    }
}

/// The address space each run may use: big enough for lavapipe and the
/// debug binary, small enough that an unbounded allocation fails here
/// instead of exhausting the machine.
const MEMORY_LIMIT: u64 = 8 << 30;
const TIME_LIMIT: Duration = Duration::from_secs(60);
/// Open files each run may hold: the usual default of Linux shells.
#[cfg(unix)]
const OPEN_FILES: libc::rlim_t = 1024;

fn hostile_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/hostile")
}

/// Whether a GPU adapter (lavapipe counts) can be opened here.
fn gpu_available() -> bool {
    // As the binary does (main.rs): without a runtime folder, Mesa's
    // device-select layer would complain of it while listing GPUs.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: called before the test starts any thread of its own.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
    pelage_gpu::GpuContext::headless().is_ok()
}

/// Runs the case's command in `dir` under the limits: its exit status
/// (`None`: it timed out and was killed), stdout and stderr.
fn run_binary(case: &Case, dir: &Path) -> (Option<std::process::ExitStatus>, String, String) {
    // Another binary can be tried (an older build, to see that new cases
    // fail there).
    let binary = std::env::var_os("PELAGE_HOSTILE_BINARY").map_or_else(
        || PathBuf::from(env!("CARGO_BIN_EXE_pelage")),
        PathBuf::from,
    );
    let mut command = Command::new(binary);
    command
        .args(&case.args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        // SAFETY: only setrlimit, which is async-signal-safe, runs between
        // fork and exec.
        unsafe {
            command.pre_exec(|| {
                let limit = libc::rlimit {
                    rlim_cur: MEMORY_LIMIT as libc::rlim_t,
                    rlim_max: MEMORY_LIMIT as libc::rlim_t,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                // The usual limit of open files, whatever this machine's.
                let files = libc::rlimit {
                    rlim_cur: OPEN_FILES,
                    rlim_max: OPEN_FILES,
                };
                if libc::setrlimit(libc::RLIMIT_NOFILE, &files) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    let start = Instant::now();
    let mut child = command.spawn().unwrap();
    // Read the pipes on threads so a chatty run cannot block on a full one.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut out, &mut s).ok();
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut err, &mut s).ok();
        s
    });
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let (stdout, stderr) = (out.join().unwrap(), err.join().unwrap());
    (status, stdout, stderr)
}

/// Runs one case; the problems found, empty when it passed.
fn run_case(case: &Case) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    for file in &case.files {
        let from = hostile_folder().join(file);
        // A folder brings its files.
        let sources = match std::fs::read_dir(&from) {
            Ok(entries) => entries.map(|e| e.unwrap().path()).collect(),
            Err(_) => vec![from],
        };
        for from in sources {
            let name = from.file_name().unwrap();
            std::fs::copy(&from, dir.path().join(name))
                .unwrap_or_else(|e| panic!("{}: {}: {e}", case.name, from.display()));
        }
    }
    for (name, text) in &case.write {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
    }
    let before: BTreeMap<&String, Vec<u8>> = case
        .unchanged
        .iter()
        .map(|f| (f, std::fs::read(dir.path().join(f)).unwrap()))
        .collect();

    let (status, stdout, stderr) = run_binary(case, dir.path());
    // Outputs that a second run must write byte for byte the same.
    let mut again_problems = Vec::new();
    if !case.reproducible.is_empty() {
        let first: Vec<Option<Vec<u8>>> = case
            .reproducible
            .iter()
            .map(|f| std::fs::read(dir.path().join(f)).ok())
            .collect();
        run_binary(case, dir.path());
        for (file, bytes) in case.reproducible.iter().zip(first) {
            match (bytes, std::fs::read(dir.path().join(file)).ok()) {
                (Some(a), Some(b)) if a == b => {}
                (None, _) | (_, None) => again_problems.push(format!("{file} was not written")),
                _ => again_problems.push(format!("{file} differs between two runs")),
            }
        }
    }

    let mut problems = again_problems;
    match status {
        None => problems.push(format!("timed out after {TIME_LIMIT:?}")),
        Some(status) => match status.code() {
            None => problems.push(format!(
                "killed by a signal ({status}): an abort or a crash"
            )),
            Some(code) if !case.exit.admits(code) => {
                problems.push(format!("exit code {code}, expected {:?}", case.exit))
            }
            Some(2) if !stderr.starts_with("error: ") => {
                problems.push("exit 2 without an `error: …` message".into())
            }
            // clap's own errors end with a hint line; pelage's are one line.
            Some(2) if stderr.trim_end().lines().count() > 1 && !stderr.contains("--help") => {
                problems.push("the error spans more than one line".into())
            }
            Some(_) => {}
        },
    }
    if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") {
        problems.push("it panicked".into());
    }
    for piece in &case.stderr {
        if !stderr.contains(piece.as_str()) {
            problems.push(format!("stderr lacks {piece:?}"));
        }
    }
    if let Some(most) = case.stderr_at_most
        && stderr.len() > most
    {
        problems.push(format!(
            "stderr is {} bytes, more than {most}",
            stderr.len()
        ));
    }
    for (file, pieces) in &case.contains {
        let text = std::fs::read_to_string(dir.path().join(file)).unwrap_or_default();
        for piece in pieces {
            if !text.contains(piece.as_str()) {
                problems.push(format!("{file} lacks {piece:?}"));
            }
        }
    }
    for piece in &case.stdout {
        if !stdout.contains(piece.as_str()) {
            problems.push(format!("stdout lacks {piece:?}"));
        }
    }
    for (file, bytes) in &before {
        if std::fs::read(dir.path().join(file)).ok().as_ref() != Some(bytes) {
            problems.push(format!("{file} was changed"));
        }
    }
    for file in &case.absent {
        if dir.path().join(file).exists() {
            problems.push(format!("{file} exists"));
        }
    }
    for file in &case.present {
        if !dir.path().join(file).exists() {
            problems.push(format!("{file} was not written"));
        }
    }
    for file in &case.not_blank {
        match image::open(dir.path().join(file)) {
            Ok(image) => {
                let image = image.to_rgba8();
                let corner = *image.get_pixel(0, 0);
                let differing = image.pixels().filter(|p| **p != corner).count();
                if differing * 100 < image.pixels().len() {
                    problems.push(format!("{file} is blank ({differing} pixels differ)"));
                }
            }
            Err(e) => problems.push(format!("{file}: {e}")),
        }
    }
    for entry in walk(dir.path()) {
        let name = entry.file_name().unwrap().to_string_lossy().into_owned();
        if name.contains(".tmp-") && !case.allow_temporary.contains(&name) {
            problems.push(format!("a temporary file was left: {name}"));
        }
    }
    if !problems.is_empty() {
        let short = |s: &str| s.chars().take(2000).collect::<String>();
        problems.push(format!(
            "stdout: {}\nstderr: {}",
            short(&stdout),
            short(&stderr)
        ));
    }
    problems
}

/// Every file under `dir`.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            files.extend(walk(&path));
        } else {
            files.push(path);
        }
    }
    files
}

#[test]
fn hostile_inputs_end_in_clear_errors_or_correct_results() {
    let text = std::fs::read_to_string(hostile_folder().join("cases.toml")).unwrap();
    let manifest: Manifest = toml::from_str(&text).expect("cases.toml parses");
    let gpu = gpu_available();
    if !gpu && std::env::var_os("PELAGE_REQUIRE_GPU").is_some() {
        panic!("PELAGE_REQUIRE_GPU is set and no GPU adapter was found");
    }
    // PELAGE_HOSTILE_ONLY=name,name runs only those cases.
    let only = std::env::var("PELAGE_HOSTILE_ONLY").ok();
    let chosen = |c: &&Case| {
        only.as_ref()
            .is_none_or(|o| o.split(',').any(|n| n == c.name))
    };
    let cases: Vec<&Case> = manifest
        .case
        .iter()
        .filter(|c| gpu || !c.gpu)
        .filter(chosen)
        .collect();
    let skipped = manifest.case.len() - cases.len();
    // Two at a time: the cases are small, the machines have two cores.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some(case) = cases.get(i) else { break };
                    let started = Instant::now();
                    let problems = run_case(case);
                    eprintln!(
                        "{} {} ({:.1} s)",
                        if problems.is_empty() { "ok  " } else { "FAIL" },
                        case.name,
                        started.elapsed().as_secs_f64()
                    );
                    if !problems.is_empty() {
                        failures.lock().unwrap().push(format!(
                            "{}:\n  {}",
                            case.name,
                            problems.join("\n  ")
                        ));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    eprintln!(
        "{} hostile cases run, {skipped} skipped (no GPU, or not in PELAGE_HOSTILE_ONLY), {} failed",
        cases.len(),
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
