//! Writing outputs so that a write cannot be turned against the user and a failed or
//! interrupted run leaves nothing half written.
//!
//! Each output is first written to a temporary file created exclusively (`O_CREAT|O_EXCL`,
//! which also refuses a symbolic link planted at its name) under a name of bounded length
//! `.toposmooth-PID-RANDOM.tmp[.EXT]`, held under an advisory lock (`flock`) while it is in use:
//!
//! - a regular target (or a new one) gets its temporary beside it and is replaced by a rename;
//! - a FIFO or character device (`/dev/null`, `/dev/stdout`, a named pipe) is never renamed
//!   over: its temporary lives in the system's temporary directory, is read back and checked
//!   like any other, and its bytes are then copied into the target;
//! - a directory, socket or block device is refused before any work.
//!
//! [`reserve`] creates the temporaries of a command's outputs before any computation (which
//! proves that each directory exists and is writable); [`stage`] fills one; [`commit_all`]
//! renames a command's outputs into place together, under a lock that the interrupt handler
//! also takes, so SIGINT or SIGTERM never lands between two renames. [`remove_temporaries`]
//! removes every temporary this process still holds (the interrupt handler calls it). A run
//! killed with SIGKILL can leave its temporaries: the next run that writes into that directory
//! removes those whose lock is free (their process is gone).

use crate::error::{Error, Result};
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// The prefix of every temporary file's name.
pub const TEMP_PREFIX: &str = ".toposmooth-";
/// The suffix of every temporary file's name.
pub const TEMP_SUFFIX: &str = ".tmp";

/// How an output target is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetKind {
    /// A new or regular file: replaced by renaming a temporary sibling over it.
    Replace,
    /// A FIFO or character device: written directly, never renamed over.
    Stream,
}

/// A temporary file this process created and holds locked.
struct Temp {
    path: PathBuf,
    file: File,
}

/// A reserved output: its target, how it is written and its temporary.
struct Reservation {
    target: PathBuf,
    kind: TargetKind,
    temp: Temp,
}

/// The temporaries this process holds (paths), for [`remove_temporaries`].
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// The same paths as C strings, made when each temporary is, so that they can be removed
/// where nothing may be allocated ([`remove_temporaries_unallocated`]).
#[cfg(unix)]
static LIVE_C: Mutex<Vec<std::ffi::CString>> = Mutex::new(Vec::new());
/// Outputs reserved by [`reserve`] and not yet staged.
static RESERVED: Mutex<Vec<Reservation>> = Mutex::new(Vec::new());
/// Held while a command's outputs are renamed into place, and by [`remove_temporaries`].
static COMMIT: Mutex<()> = Mutex::new(());
/// Directories already cleared of stale temporaries by this process.
static CLEANED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.to_path_buf(), source }
}

/// Says how `path` would be written, or why it cannot be: a directory, a socket, a block
/// device, a missing directory or a parent that is not one are errors naming the path.
///
/// # Errors
/// [`Error::Usage`] for a target that cannot be written; [`Error::Io`] when its status
/// cannot be read.
pub fn target_kind(path: &Path) -> Result<TargetKind> {
    #[cfg(unix)]
    use std::os::unix::fs::FileTypeExt;
    let usage = |what: &str| Err(Error::Usage(format!("{}: {what}", path.display())));
    if path.as_os_str().is_empty() {
        return usage("an empty output name");
    }
    if is_stdout(path) {
        return Ok(TargetKind::Stream);
    }
    match std::fs::metadata(path) {
        Ok(m) => {
            let t = m.file_type();
            if t.is_file() {
                return Ok(TargetKind::Replace);
            }
            if t.is_dir() {
                return usage("is a directory, not an output file");
            }
            #[cfg(unix)]
            {
                if t.is_fifo() || t.is_char_device() {
                    return Ok(TargetKind::Stream);
                }
                if t.is_block_device() {
                    return usage("is a block device; toposmooth does not write to one");
                }
                if t.is_socket() {
                    return usage("is a socket; toposmooth does not write to one");
                }
            }
            usage("is a special file, not a regular file, FIFO or character device")
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let dir = parent(path);
            match std::fs::metadata(&dir) {
                Ok(m) if m.is_dir() => Ok(TargetKind::Replace),
                Ok(_) => usage(&format!("{} is not a directory", dir.display())),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    usage(&format!("the directory {} does not exist", dir.display()))
                }
                Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => {
                    usage(&format!("{} is not a directory", dir.display()))
                }
                Err(e) => Err(io_error(&dir, e)),
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => {
            usage(&format!("{} is not a directory", parent(path).display()))
        }
        Err(e) => Err(io_error(path, e)),
    }
}

/// Whether `path` is `-`, the standard output.
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Whether `path` is written as a stream (`-`, a FIFO or a character device): such a target
/// has no file name to say its format, so an output without an extension there takes the
/// domain's streamable format.
pub fn is_stream(path: &Path) -> bool {
    matches!(target_kind(path), Ok(TargetKind::Stream))
}

/// Whether an output of this run goes to the standard output (then the summary goes to
/// standard error).
pub fn writes_stdout() -> bool {
    STDOUT_USED.load(std::sync::atomic::Ordering::Relaxed)
}

static STDOUT_USED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The directory a target's temporary goes to.
fn temp_dir_for(path: &Path, kind: TargetKind) -> PathBuf {
    match kind {
        TargetKind::Replace => parent(path),
        TargetKind::Stream => std::env::temp_dir(),
    }
}

/// The directory holding `path` (`.` for a bare name).
fn parent(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// 64 random bits (from the standard library's randomly keyed hasher, the clock and a counter).
fn random_part() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed));
    if let Ok(t) = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH) {
        h.write_u128(t.as_nanos());
    }
    h.finish()
}

/// Whether `name` is one of our temporaries' names.
fn is_temp_name(name: &std::ffi::OsStr) -> bool {
    name.to_str().is_some_and(|n| {
        n.strip_prefix(TEMP_PREFIX).is_some_and(|rest| {
            rest.ends_with(TEMP_SUFFIX)
                || rest.rsplit_once('.').is_some_and(|(head, ext)| {
                    head.ends_with(TEMP_SUFFIX) && ext.bytes().all(|b| b.is_ascii_alphanumeric())
                })
        })
    })
}

/// Creates `dir/name` exclusively (never through a symbolic link) and locks it.
/// `Ok(None)`: the name is taken or its lock is held (try another name).
fn create_locked(dir: &Path, name: &str) -> std::io::Result<Option<Temp>> {
    let path = dir.join(name);
    let file = match OpenOptions::new().read(true).write(true).create_new(true).open(&path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => return Ok(None),
        Err(e) => return Err(e),
    };
    let temp = Temp { path, file };
    // another run clearing stale temporaries may have opened and locked it in between
    match temp.file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => return Ok(None),
        Err(std::fs::TryLockError::Error(e)) => {
            let _ = std::fs::remove_file(&temp.path);
            return Err(e);
        }
    }
    // ... and removed it: then the name no longer leads to our file
    if !same_file(&temp.file, &temp.path) {
        return Ok(None);
    }
    Ok(Some(temp))
}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &File, path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file())
}

/// Creates a locked temporary in `dir` for `target`, registered for [`remove_temporaries`]:
/// `.toposmooth-PID-RANDOM.tmp`, followed by the target's extension when it is short, so that
/// the readers can read the temporary back as the format it holds.
fn new_temp(dir: &Path, target: &Path) -> std::io::Result<Temp> {
    clean_stale(dir);
    let ext = target
        .extension()
        .and_then(|e| e.to_str())
        .filter(|e| !e.is_empty() && e.len() <= 8 && e.bytes().all(|b| b.is_ascii_alphanumeric()))
        .map(|e| format!(".{e}"))
        .unwrap_or_default();
    for _ in 0..64 {
        let name = format!("{TEMP_PREFIX}{}-{:016x}{TEMP_SUFFIX}{ext}", std::process::id(), random_part());
        // created while LIVE is held, so that the interrupt handler sees every temporary
        let mut live = lock(&LIVE);
        if let Some(t) = create_locked(dir, &name)? {
            live.push(t.path.clone());
            #[cfg(unix)]
            {
                use std::os::unix::ffi::OsStrExt;
                if let Ok(c) = std::ffi::CString::new(t.path.as_os_str().as_bytes()) {
                    lock(&LIVE_C).push(c);
                }
            }
            return Ok(t);
        }
    }
    Err(std::io::Error::other("no free temporary name after 64 tries"))
}

/// Removes `dir`'s temporaries left by runs that are gone (their lock is free), once per
/// directory and process. Only regular files with our names are touched, never through a link.
fn clean_stale(dir: &Path) {
    let key = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    {
        let mut cleaned = lock(&CLEANED);
        if cleaned.contains(&key) {
            return;
        }
        cleaned.push(key);
    }
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let ours: Vec<PathBuf> = lock(&LIVE).clone();
    for entry in entries.flatten() {
        let path = entry.path();
        if !is_temp_name(&entry.file_name()) || ours.contains(&path) {
            continue;
        }
        if !entry.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        let Ok(file) = open_no_follow(&path) else { continue };
        if file.try_lock().is_ok() && same_file(&file, &path) {
            let _ = std::fs::remove_file(&path);
        }
    }
}

#[cfg(unix)]
fn open_no_follow(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    OpenOptions::new().read(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(path)
}

#[cfg(not(unix))]
fn open_no_follow(path: &Path) -> std::io::Result<File> {
    File::open(path)
}

/// Reserves the outputs `paths` before any work: checks that each can be written (see
/// [`target_kind`]) and creates its locked temporary, which [`stage`] then fills.
///
/// # Errors
/// As [`target_kind`]; I/O errors naming the target when its temporary cannot be created
/// (a directory that is not writable).
pub fn reserve(paths: &[&Path]) -> Result<()> {
    for &path in paths {
        if lock(&RESERVED).iter().any(|r| r.target == path) {
            continue;
        }
        let kind = target_kind(path)?;
        if is_stdout(path) {
            if writes_stdout() {
                return Err(Error::Usage("only one output can go to the standard output (`-`)".into()));
            }
            STDOUT_USED.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        let temp = new_temp(&temp_dir_for(path, kind), path).map_err(|e| io_error(path, e))?;
        lock(&RESERVED).push(Reservation { target: path.to_path_buf(), kind, temp });
    }
    Ok(())
}

/// A complete output waiting in its temporary: [`Staged::commit`] (or [`commit_all`]) puts it
/// in place; dropped uncommitted, the temporary is removed.
#[must_use = "a staged file is removed unless committed"]
pub struct Staged {
    target: PathBuf,
    kind: TargetKind,
    temp: Option<Temp>,
}

impl Staged {
    /// The target this output is for.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The temporary file holding the complete content (to read it back before committing).
    pub fn temp_path(&self) -> &Path {
        self.temp.as_ref().map_or(Path::new(""), |t| t.path.as_path())
    }

    /// Puts this output in place (see [`commit_all`] for several).
    ///
    /// # Errors
    /// I/O errors naming the target.
    pub fn commit(self) -> Result<()> {
        commit_all(vec![self])
    }

    fn commit_one(&mut self) -> Result<()> {
        let Some(temp) = self.temp.take() else { return Ok(()) };
        let result = match self.kind {
            TargetKind::Replace => std::fs::rename(&temp.path, &self.target),
            TargetKind::Stream => copy_into(&temp, &self.target).and_then(|()| std::fs::remove_file(&temp.path)),
        };
        if result.is_err() {
            let _ = std::fs::remove_file(&temp.path);
        }
        unregister(&temp.path);
        result.map_err(|e| io_error(&self.target, e))
    }
}

/// Copies a temporary's bytes into a FIFO or device, opened without truncation or creation.
fn copy_into(temp: &Temp, target: &Path) -> std::io::Result<()> {
    let mut source = &temp.file;
    source.seek(std::io::SeekFrom::Start(0))?;
    if is_stdout(target) {
        let mut out = std::io::stdout().lock();
        std::io::copy(&mut source, &mut out)?;
        return out.flush();
    }
    let mut out = OpenOptions::new().write(true).open(target)?;
    std::io::copy(&mut source, &mut out)?;
    out.flush()
}

fn unregister(path: &Path) {
    lock(&LIVE).retain(|p| p != path);
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        lock(&LIVE_C).retain(|c| c.as_bytes() != path.as_os_str().as_bytes());
    }
}

/// Removes the temporaries this process holds without allocating (for a failed allocation:
/// the tool's allocator calls it before it exits); a list locked by the failing thread itself
/// is left.
pub fn remove_temporaries_unallocated() {
    #[cfg(unix)]
    if let Ok(list) = LIVE_C.try_lock() {
        for c in list.iter() {
            // SAFETY: a NUL-terminated path kept alive by the list
            unsafe { libc::unlink(c.as_ptr()) };
        }
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            let _ = std::fs::remove_file(&temp.path);
            unregister(&temp.path);
        }
    }
}

/// Puts every staged output in place, in order, under the lock the interrupt handler takes
/// (an interrupt waits for the renames to finish). On the first failure the rest are removed.
///
/// # Errors
/// The first I/O error, naming its target.
pub fn commit_all(staged: Vec<Staged>) -> Result<()> {
    let _guard = lock(&COMMIT);
    let mut first = None;
    for mut s in staged {
        if first.is_none() {
            if let Err(e) = s.commit_one() {
                first = Some(e);
            }
        }
    }
    first.map_or(Ok(()), Err)
}

/// Removes every temporary this process holds (reserved, staged or being written); waits for
/// a commit in progress. The interrupt handler and the tool's exit call it.
pub fn remove_temporaries() {
    let _guard = lock(&COMMIT);
    lock(&RESERVED).clear();
    // LIVE stays locked: no temporary can be created after this
    let mut live = lock(&LIVE);
    for p in live.drain(..) {
        let _ = std::fs::remove_file(&p);
    }
    std::mem::forget(live);
}

/// Removes the temporaries of outputs reserved and not staged (a command that failed or was
/// cancelled before writing them): for a process that goes on after a command, as the Python
/// package's in-process commands do ([`remove_temporaries`] is for a process about to end).
pub fn discard_reserved() {
    let reserved: Vec<Reservation> = lock(&RESERVED).drain(..).collect();
    for r in reserved {
        let _ = std::fs::remove_file(&r.temp.path);
        unregister(&r.temp.path);
    }
}

/// Stages `path`: `fill` writes the complete content into its temporary (reserved by
/// [`reserve`], or created now), which is then flushed and synced. A replaced regular file's
/// permissions are kept.
///
/// # Errors
/// As [`reserve`]; the writer's I/O errors, naming the target.
pub fn stage_with(path: &Path, fill: impl FnOnce(&mut BufWriter<&File>) -> std::io::Result<()>) -> Result<Staged> {
    let reserved = {
        let mut r = lock(&RESERVED);
        r.iter().position(|x| x.target == path).map(|i| r.swap_remove(i))
    };
    let (kind, temp) = match reserved {
        Some(r) => (r.kind, r.temp),
        None => {
            let kind = target_kind(path)?;
            (kind, new_temp(&temp_dir_for(path, kind), path).map_err(|e| io_error(path, e))?)
        }
    };
    let staged = Staged { target: path.to_path_buf(), kind, temp: Some(temp) };
    let file = &staged.temp.as_ref().expect("just set").file;
    let write = || -> std::io::Result<()> {
        file.set_len(0)?;
        let mut w = BufWriter::new(file);
        w.rewind()?;
        fill(&mut w)?;
        w.flush()?;
        drop(w);
        if kind == TargetKind::Replace {
            if let Ok(m) = std::fs::metadata(path) {
                if m.is_file() {
                    file.set_permissions(m.permissions())?;
                }
            }
        }
        file.sync_all()
    };
    write().map_err(|e| io_error(path, e))?;
    Ok(staged)
}

/// Stages `path`: `fill` writes the content (see [`stage_with`]).
///
/// # Errors
/// As [`stage_with`].
pub fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<Staged> {
    stage_with(path, |w| fill(w))
}

/// Writes `path` at once: [`stage`] then [`Staged::commit`].
///
/// # Errors
/// As [`stage`] and [`commit_all`].
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    stage(path, fill)?.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("toposmooth-staging-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn a_failed_write_leaves_nothing_and_a_good_one_only_the_target() {
        let dir = scratch("atomic");
        let target = dir.join("x.txt");
        let r = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert!(names(&dir).is_empty(), "{:?}", names(&dir));
        write_atomic(&target, |w| w.write_all(b"ok")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "ok");
        assert_eq!(names(&dir), ["x.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_a_temporary_name_is_refused_and_its_target_untouched() {
        let dir = scratch("link");
        let victim = dir.join("victim");
        std::fs::write(&victim, "precious").unwrap();
        std::os::unix::fs::symlink(&victim, dir.join(".toposmooth-1-planted.tmp")).unwrap();
        assert!(create_locked(&dir, ".toposmooth-1-planted.tmp").unwrap().is_none());
        // a dangling link too
        std::os::unix::fs::symlink(dir.join("nowhere"), dir.join(".toposmooth-2-planted.tmp")).unwrap();
        assert!(create_locked(&dir, ".toposmooth-2-planted.tmp").unwrap().is_none());
        assert!(!dir.join("nowhere").exists());
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn stale_temporaries_are_removed_only_when_their_lock_is_free() {
        let dir = scratch("stale");
        let stale = dir.join(".toposmooth-1-0000000000000001.tmp");
        let held = dir.join(".toposmooth-2-0000000000000002.tmp");
        let other = dir.join(".other.tmp");
        std::fs::write(&stale, "left by a killed run").unwrap();
        std::fs::write(&held, "in use").unwrap();
        std::fs::write(&other, "not ours").unwrap();
        // another open file description holds the lock, as another process would
        let holder = OpenOptions::new().read(true).open(&held).unwrap();
        holder.lock().unwrap();
        write_atomic(&dir.join("out.txt"), |w| w.write_all(b"x")).unwrap();
        assert!(!stale.exists());
        assert!(held.exists());
        assert!(other.exists());
        drop(holder);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn long_and_non_utf8_names_get_their_own_temporaries() {
        let dir = scratch("names");
        let long = dir.join(format!("{}.csv", "n".repeat(251)));
        write_atomic(&long, |w| w.write_all(b"long")).unwrap();
        assert_eq!(std::fs::read_to_string(&long).unwrap(), "long");
        #[cfg(unix)]
        {
            use std::os::unix::ffi::OsStrExt;
            let a = dir.join(std::ffi::OsStr::from_bytes(b"out\xff.csv"));
            let b = dir.join(std::ffi::OsStr::from_bytes(b"out\xfe.csv"));
            let sa = stage(&a, |w| w.write_all(b"a")).unwrap();
            let sb = stage(&b, |w| w.write_all(b"b")).unwrap();
            assert_ne!(sa.temp_path(), sb.temp_path());
            commit_all(vec![sa, sb]).unwrap();
            assert_eq!(std::fs::read(&a).unwrap(), b"a");
            assert_eq!(std::fs::read(&b).unwrap(), b"b");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn directories_and_missing_directories_are_refused_before_work() {
        let dir = scratch("kinds");
        assert!(matches!(target_kind(&dir), Err(Error::Usage(m)) if m.contains("is a directory")));
        let missing = dir.join("no/such/x.vti");
        assert!(matches!(target_kind(&missing), Err(Error::Usage(m)) if m.contains("does not exist")));
        std::fs::write(dir.join("file"), "").unwrap();
        assert!(matches!(target_kind(&dir.join("file/x.vti")), Err(Error::Usage(m)) if m.contains("not a directory")));
        assert_eq!(target_kind(&dir.join("new.vti")).unwrap(), TargetKind::Replace);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_in_place_and_never_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("fifo");
        let fifo = dir.join("pipe");
        let c = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert_eq!(target_kind(&fifo).unwrap(), TargetKind::Stream);
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        let staged = stage(&fifo, |w| w.write_all(b"through the pipe")).unwrap();
        assert!(!staged.temp_path().starts_with(&dir), "the temporary of a FIFO is not beside it");
        staged.commit().unwrap();
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert_eq!(names(&dir), ["pipe"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("perm");
        let target = dir.join("x.csv");
        std::fs::write(&target, "old").unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&target, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::metadata(&target).unwrap().permissions().mode() & 0o777, 0o640);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
