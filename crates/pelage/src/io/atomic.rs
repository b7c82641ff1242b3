//! Atomic file output: temporary file in the target's folder, then rename.
//!
//! Around that core, what keeps an interrupted or mistaken run from
//! leaving damage behind:
//!
//! - every temporary file being written is listed, so a signal handler can
//!   remove them all ([`remove_temporary_files`]; the CLI calls it on
//!   SIGINT, SIGTERM and SIGHUP);
//! - temporary files that a killed process left beside a target (`kill
//!   -9`, a power cut) are removed by the next write to that target: their
//!   names carry the host and process id, and a process that no longer
//!   runs on this host will not come back for them;
//! - a program can mark the files it read as inputs
//!   ([`protect_inputs`]), and writing over one is then an error instead
//!   of a silently destroyed mesh or groom file;
//! - [`check_free_space`] refuses work whose output cannot fit the disk
//!   before the work starts.

use super::WriteError;
use std::collections::HashSet;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// The temporary files being written now, by any thread.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Set (under [`LIVE`]'s lock) once [`remove_temporary_files`] has swept:
/// the process is on its way out, and no new temporary file may appear
/// after the sweep.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Whether [`note_input`] records inputs, and the inputs it recorded
/// (canonical paths).
static PROTECTING: AtomicBool = AtomicBool::new(false);
static INPUTS: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);

/// From now on, the files this process reads (meshes, guides, maps,
/// groom and scene files: every loader calls [`note_input`]) cannot be
/// written over by it: [`AtomicFile::create`] refuses them. For programs
/// whose outputs must never replace their inputs, such as the CLI; off by
/// default, since a long-lived program may mean to rewrite a file it read
/// earlier.
pub fn protect_inputs() {
    PROTECTING.store(true, Ordering::SeqCst);
}

/// Records `path` as an input of this process, when [`protect_inputs`] is
/// on. Loaders call it; a path that does not exist is ignored.
pub fn note_input(path: &Path) {
    if !PROTECTING.load(Ordering::Relaxed) {
        return;
    }
    if let Ok(canonical) = path.canonicalize() {
        let mut inputs = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
        inputs.get_or_insert_with(HashSet::new).insert(canonical);
    }
}

/// What every reader of a file does first: refuses a folder (`what` names
/// the file wanted, "a mesh file (.obj, …)"), and records the file with
/// [`note_input`]. Each reader wraps the error in its own type.
pub fn check_input(path: &Path, what: &str) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            format!("it is a folder; give {what}"),
        ));
    }
    note_input(path);
    Ok(())
}

/// The folder a file of `path` lives in (`.` for a bare name).
pub(crate) fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Whether `path` names a file recorded by [`note_input`].
fn is_input(path: &Path) -> bool {
    if !PROTECTING.load(Ordering::Relaxed) {
        return false;
    }
    let Ok(canonical) = path.canonicalize() else {
        return false;
    };
    let inputs = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
    inputs.as_ref().is_some_and(|i| i.contains(&canonical))
}

/// Removes every temporary file this process is writing now. For signal
/// handlers (run from an ordinary thread, as `signal-hook`'s iterator
/// does, not from the handler itself): afterwards the process should exit,
/// since the writers' files are gone.
pub fn remove_temporary_files() {
    remove_temporary_files_under(None);
}

/// [`remove_temporary_files`] for the files under `folder` only (`None`:
/// all of them).
fn remove_temporary_files_under(folder: Option<&Path>) {
    let live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
    if folder.is_none() {
        CLOSED.store(true, Ordering::SeqCst);
    }
    for temp in live
        .iter()
        .filter(|t| folder.is_none_or(|f| t.starts_with(f)))
    {
        let _ = std::fs::remove_file(temp);
    }
}

/// This host's name, for temporary file names (a folder may be shared by
/// several machines of a farm: only this host's dead processes are
/// known to be dead).
fn host_name() -> &'static str {
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(read_host_name)
}

fn read_host_name() -> String {
    #[cfg(unix)]
    {
        let mut buffer = [0u8; 256];
        // SAFETY: the buffer is valid for its length; gethostname writes
        // at most that many bytes.
        let ok = unsafe { libc::gethostname(buffer.as_mut_ptr().cast(), buffer.len()) } == 0;
        if ok {
            let end = buffer.iter().position(|&b| b == 0).unwrap_or(buffer.len());
            let name: String = String::from_utf8_lossy(&buffer[..end])
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '.' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            if !name.is_empty() {
                return name;
            }
        }
    }
    "host".to_string()
}

/// Whether process `pid` runs on this host.
fn process_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return false;
        };
        // SAFETY: signal 0 only checks that the process exists.
        if unsafe { libc::kill(pid, 0) } == 0 {
            return true;
        }
        std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Removes the temporary files beside `path` that processes of this host
/// which no longer run left behind: `.NAME.tmp-HOST-PID`, and the
/// `.NAME.tmp-PID` of earlier versions.
fn remove_stale_temporary_files(path: &Path, name: &str, host: &str) {
    let Ok(entries) = std::fs::read_dir(folder_of(path)) else {
        return;
    };
    let prefix = format!(".{name}.tmp-");
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(rest) = file_name.to_str().and_then(|n| n.strip_prefix(&prefix)) else {
            continue;
        };
        let (owner, pid) = match rest.rsplit_once('-') {
            Some((owner, pid)) => (owner, pid),
            None => (host, rest),
        };
        let Ok(pid) = pid.parse::<u32>() else {
            continue;
        };
        if owner == host && pid != std::process::id() && !process_alive(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Refuses work whose output, at least `bytes` long, cannot fit the free
/// space of the disk that holds `path` (its folder when it does not exist
/// yet). Where free space cannot be asked (not Unix, no such folder yet),
/// nothing is refused.
pub fn check_free_space(path: &Path, bytes: u64) -> Result<(), WriteError> {
    let Some(free) = free_space(path) else {
        return Ok(());
    };
    if bytes <= free {
        return Ok(());
    }
    let gb = |b: u64| b as f64 / 1e9;
    Err(WriteError {
        path: path.to_path_buf(),
        error: std::io::Error::new(
            std::io::ErrorKind::StorageFull,
            format!(
                "the output needs at least {:.1} GB and the disk has {:.1} GB free; free some space, write elsewhere, or ask for fewer hairs, points or frames",
                gb(bytes),
                gb(free)
            ),
        ),
    })
}

/// Bytes free for an unprivileged user on the disk of `path`.
fn free_space(path: &Path) -> Option<u64> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let folder = if path.is_dir() { path } else { folder_of(path) };
        let c_path = std::ffi::CString::new(folder.as_os_str().as_bytes()).ok()?;
        let mut stats = std::mem::MaybeUninit::<libc::statvfs>::uninit();
        // SAFETY: a valid C string and a buffer of the right type.
        if unsafe { libc::statvfs(c_path.as_ptr(), stats.as_mut_ptr()) } != 0 {
            return None;
        }
        // SAFETY: statvfs succeeded and filled it.
        let stats = unsafe { stats.assume_init() };
        #[allow(clippy::unnecessary_cast)] // the fields' types differ by platform
        Some((stats.f_bavail as u64).saturating_mul(stats.f_frsize as u64))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// Whether `path` may be written: a file name, not a folder, not a
/// device, pipe or socket (a rename would put a regular file in its
/// place), and (under [`protect_inputs`]) not a file this process read.
/// [`AtomicFile::create`] checks it; long work checks it before it
/// starts, so a mistaken output is refused at once rather than after
/// minutes of growing.
pub fn check_output(path: &Path) -> Result<(), WriteError> {
    let fail = |kind, message: &str| WriteError {
        path: path.to_path_buf(),
        error: std::io::Error::new(kind, message),
    };
    if path.file_name().is_none() {
        return Err(fail(
            std::io::ErrorKind::InvalidInput,
            "the path names no file; give a file name",
        ));
    }
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
        && !meta.is_dir()
    {
        return Err(fail(
            std::io::ErrorKind::InvalidInput,
            "it is not a regular file (a device, a pipe or a socket): writing would replace it; give a file name",
        ));
    }
    if path.is_dir() {
        return Err(fail(
            std::io::ErrorKind::IsADirectory,
            "it is a folder; give a file name",
        ));
    }
    if is_input(path) {
        return Err(fail(
            std::io::ErrorKind::AlreadyExists,
            "it is an input of this run; writing over it would destroy it: choose another output",
        ));
    }
    Ok(())
}

/// Whether `path` can be written now: [`check_output`] holds and its
/// folder takes a file (a temporary file is made beside it and removed).
/// Long work (a simulation) calls it before it starts, so an output in a
/// folder that is not there is refused at once, not after minutes.
pub fn check_writable(path: &Path) -> Result<(), WriteError> {
    AtomicFile::create(path).map(drop)
}

/// A file being written atomically, for writers that hold their output
/// (several files open at once): a buffered temporary file beside the
/// target, renamed over it by [`Self::commit`]; dropped uncommitted, the
/// temporary file is removed and the target left as it was.
pub struct AtomicFile {
    path: std::path::PathBuf,
    temp: std::path::PathBuf,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `path`. Refused when `path` is a folder or, under
    /// [`protect_inputs`], a file this process read.
    pub fn create(path: &Path) -> Result<Self, WriteError> {
        let fail = |error| WriteError {
            path: path.to_path_buf(),
            error,
        };
        let name = path
            .file_name()
            .ok_or_else(|| fail(std::io::Error::other("the path names no file")))?
            .to_string_lossy()
            .into_owned();
        check_output(path)?;
        let host = host_name();
        remove_stale_temporary_files(path, &name, host);
        let temp = path.with_file_name(format!(".{name}.tmp-{host}-{}", std::process::id()));
        // Created and listed under the list's lock: a signal's sweep comes
        // wholly before (and then no file is created) or after (and finds
        // it), never between creating and listing.
        let file = {
            let mut live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
            if CLOSED.load(Ordering::SeqCst) {
                return Err(fail(std::io::Error::new(
                    std::io::ErrorKind::Interrupted,
                    "the run was interrupted",
                )));
            }
            let file = File::create(&temp).map_err(fail)?;
            live.push(temp.clone());
            file
        };
        Ok(Self {
            path: path.to_path_buf(),
            temp,
            out: Some(BufWriter::with_capacity(1 << 20, file)),
        })
    }

    /// The target's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the file over its target.
    pub fn commit(mut self) -> Result<(), WriteError> {
        let out = self.out.take().expect("an uncommitted file has its writer");
        let result = (|| {
            let file = out.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            drop(file);
            std::fs::rename(&self.temp, &self.path)
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&self.temp);
        }
        unlist(&self.temp);
        result.map_err(|error| WriteError {
            path: self.path.clone(),
            error,
        })
    }

    fn writer(&mut self) -> &mut BufWriter<File> {
        self.out
            .as_mut()
            .expect("an uncommitted file has its writer")
    }
}

/// Takes `temp` off the list of temporary files being written.
fn unlist(temp: &Path) {
    let mut live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(i) = live.iter().position(|t| t == temp) {
        live.swap_remove(i);
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer().write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.writer().write_all(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.writer().flush()
    }
}

impl std::io::Seek for AtomicFile {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.writer().seek(pos)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.temp);
            unlist(&self.temp);
        }
    }
}

/// [`write_atomically`] for a body with errors of its own type `E` (a
/// streamed groom's: a part that did not grow), kept as they are instead
/// of flattened into I/O errors; the file's own errors (creating, syncing,
/// renaming) become `E` through `From<WriteError>`.
pub fn write_atomically_with<E: From<WriteError>>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), E>,
) -> Result<(), E> {
    let mut file = AtomicFile::create(path)?;
    // On an error the file is dropped uncommitted: its temporary is removed.
    write(file.writer())?;
    Ok(file.commit()?)
}

/// Writes `path` by calling `write` on a buffered temporary file in the
/// same folder (`.NAME.tmp-HOST-PID`), flushing and syncing it, and renaming it
/// over `path`. On any error the temporary file is removed and `path` is
/// left as it was.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    let mut file = AtomicFile::create(path)?;
    // On an error the file is dropped uncommitted: its temporary is removed.
    write(file.writer()).map_err(|error| WriteError {
        path: path.to_path_buf(),
        error,
    })?;
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failing_writer_leaves_neither_target_nor_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.ply");
        std::fs::write(&target, b"old contents").unwrap();
        let err = write_atomically(&target, |w| {
            w.write_all(b"half a file")?;
            Err(std::io::Error::other("interrupted"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("out.ply: interrupted"), "{err}");
        assert_eq!(std::fs::read(&target).unwrap(), b"old contents");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "a temporary file was left behind");
    }

    #[test]
    fn an_atomic_file_dropped_uncommitted_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a.usdc");
        let mut file = AtomicFile::create(&target).unwrap();
        file.write_all(b"half").unwrap();
        drop(file);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let mut file = AtomicFile::create(&target).unwrap();
        file.write_all(b"whole").unwrap();
        file.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"whole");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn temporary_files_of_dead_processes_are_removed_by_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.usdc");
        let host = host_name();
        // No process has a pid this large (Linux's ceiling is 2^22).
        let dead = [
            format!(".out.usdc.tmp-{host}-2147483647"),
            ".out.usdc.tmp-2147483646".to_string(),
        ];
        // Pid 1 runs; another host's processes are not ours to judge.
        let kept = [
            format!(".out.usdc.tmp-{host}-1"),
            ".out.usdc.tmp-elsewhere-2147483647".to_string(),
            ".other.usdc.tmp-2147483647".to_string(),
        ];
        for name in dead.iter().chain(&kept) {
            std::fs::write(dir.path().join(name), b"debris").unwrap();
        }
        write_atomically(&target, |w| w.write_all(b"new")).unwrap();
        for name in &dead {
            assert!(!dir.path().join(name).exists(), "{name} was left");
        }
        for name in &kept {
            assert!(dir.path().join(name).exists(), "{name} was removed");
        }
    }

    #[test]
    fn a_signal_handler_can_remove_the_files_being_written() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("sequence.usdc");
        let mut file = AtomicFile::create(&target).unwrap();
        file.write_all(b"half").unwrap();
        let temporary = || {
            std::fs::read_dir(dir.path())
                .unwrap()
                .filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .file_name()
                        .to_string_lossy()
                        .contains(".tmp-")
                })
                .count()
        };
        assert_eq!(temporary(), 1);
        // Only this test's: other tests of this process write beside it.
        remove_temporary_files_under(Some(dir.path()));
        assert_eq!(temporary(), 0);
        // The writer's commit then fails: its file is gone.
        assert!(file.commit().is_err());
        assert!(!target.exists());
    }

    #[test]
    fn output_that_cannot_fit_the_disk_is_refused_before_it_starts() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("huge.usdc");
        check_free_space(&target, 0).unwrap();
        let err = check_free_space(&target, u64::MAX).unwrap_err().to_string();
        assert!(
            err.contains("huge.usdc") && err.contains("GB free"),
            "{err}"
        );
    }

    #[test]
    fn a_folder_is_not_a_file_to_write() {
        let dir = tempfile::tempdir().unwrap();
        let err = write_atomically(dir.path(), |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(err.contains("it is a folder"), "{err}");
    }

    #[test]
    fn success_replaces_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        write_atomically(&target, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
    }

    #[test]
    fn a_missing_folder_is_an_error_naming_the_file() {
        let err = write_atomically(Path::new("/no/such/folder/x.ply"), |_| Ok(())).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("cannot write /no/such/folder/x.ply:"),
            "{err}"
        );
    }
}
