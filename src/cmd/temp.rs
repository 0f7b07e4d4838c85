//! Temporary files and folders of the commands' outputs: unpredictable names beside the target
//! (`.NAME.tmp-` and 16 random hex digits, cut to fit 255 bytes), created exclusively and never
//! through a symbolic link, and listed in a registry that the signal cleanup
//! ([`remove_temp_files`]) empties. Invariant: an entry is created and registered in one
//! critical section, and renamed into place or removed and unregistered in one, so the cleanup
//! removes exactly what this process made and has not put in place. Not here: what is written
//! into them, or which outputs are written directly (`super::io`).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Longest file name most file systems take (`NAME_MAX`).
const NAME_MAX: usize = 255;
/// What a temporary name adds to the stem: `.` before, `.tmp-` and 16 hex digits after.
const TEMP_NAME_EXTRA: usize = 1 + ".tmp-".len() + 16;

/// A temporary name beside `path`: `.NAME.tmp-` and 16 hex digits of `random`, NAME cut (at a
/// character boundary) so that the whole fits in [`NAME_MAX`] bytes (a 255-byte NAME works).
/// `what` is `tmp`, or `old` for a folder renamed aside.
pub(super) fn temp_name(path: &Path, what: &str, random: u64) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let mut cut = name.len().min(NAME_MAX - TEMP_NAME_EXTRA);
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    path.with_file_name(format!(".{}.{what}-{random:016x}", &name[..cut]))
}

/// 64 unpredictable bits for a temporary name: SipHash, keyed by the standard library's
/// `RandomState` (seeded from the operating system's random source once per thread, then
/// changed for every new state), of a counter, the process id and the time. The names need not
/// be secret, only not guessable in advance: they are created exclusively anyway.
pub(super) fn random_suffix() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(COUNT.fetch_add(1, Ordering::Relaxed));
    h.write_u32(std::process::id());
    if let Ok(t) = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH) {
        h.write_u128(t.as_nanos());
    }
    h.finish()
}

/// Creates a new file at `path` for writing, exclusively: never an existing file, nor through a
/// symbolic link (`O_CREAT | O_EXCL`, and `O_NOFOLLOW` on Unix).
pub(crate) fn create_new_file(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW);
    }
    options.open(path)
}

/// A temporary file or folder being written now.
#[derive(Debug, PartialEq, Eq)]
enum Temp {
    File(PathBuf),
    /// Removed with all it holds.
    Folder(PathBuf),
}

impl Temp {
    fn path(&self) -> &Path {
        match self {
            Temp::File(p) | Temp::Folder(p) => p,
        }
    }

    fn remove(&self) {
        let _ = match self {
            Temp::File(p) => std::fs::remove_file(p),
            Temp::Folder(p) => std::fs::remove_dir_all(p),
        };
    }
}

/// Temporary files and folders being written now (removed by [`remove_temp_files`] on a
/// signal). Invariant: an entry is added in the same critical section that creates it, and
/// dropped in the one that renames or removes it, so the signal's cleanup, which takes the lock
/// for good, removes exactly what this process made and has not yet put in place.
static TEMP_FILES: Mutex<Vec<Temp>> = Mutex::new(Vec::new());

fn temp_files() -> std::sync::MutexGuard<'static, Vec<Temp>> {
    TEMP_FILES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Creates a temporary entry beside `path` with `create` (given a fresh unpredictable name; it
/// must fail with `AlreadyExists` when the name is taken, then another name is tried) and
/// registers it with `temp`.
fn create_temp<T>(
    path: &Path,
    create: impl Fn(&Path) -> std::io::Result<T>,
    temp: impl Fn(PathBuf) -> Temp,
) -> std::io::Result<(T, PathBuf)> {
    let mut last = None;
    for _ in 0..16 {
        let tmp = temp_name(path, "tmp", random_suffix());
        let mut files = temp_files();
        match create(&tmp) {
            Ok(made) => {
                files.push(temp(tmp.clone()));
                return Ok((made, tmp));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.expect("tried at least once"))
}

/// A new temporary file beside `path` ([`create_new_file`], [`temp_name`]), registered.
pub(super) fn create_temp_file(path: &Path) -> std::io::Result<(std::fs::File, PathBuf)> {
    create_temp(path, create_new_file, Temp::File)
}

/// A new temporary folder beside `dir` (`mkdir` fails on any existing name, a symbolic link
/// included), registered: removed with its contents on a signal.
pub(crate) fn create_temp_folder(dir: &Path) -> std::io::Result<PathBuf> {
    create_temp(dir, |p| std::fs::create_dir(p), Temp::Folder).map(|((), tmp)| tmp)
}

/// A new file `name` in the registered temporary folder `folder`, created under the registry's
/// lock: a signal's cleanup, which takes the lock for good, never removes the folder while a
/// file is being added to it (its `remove_dir_all` would then find the folder not empty and
/// leave it behind).
pub(crate) fn create_in_temp_folder(folder: &Path, name: &str) -> std::io::Result<std::fs::File> {
    let _files = temp_files();
    create_new_file(&folder.join(name))
}

/// Removes a registered temporary file or folder and drops it from the registry.
pub(crate) fn discard_temp(tmp: &Path) {
    let mut files = temp_files();
    if let Some(i) = files.iter().position(|t| t.path() == tmp) {
        files.remove(i).remove();
    }
}

/// Renames the folder `from` (a registered temporary folder) to `to`; when `to` is an existing
/// folder it is first renamed aside and returned, registered as temporary: the caller removes it
/// with [`discard_temp`]. All under the registry's lock, so a signal's cleanup comes before or
/// after, never between the renames.
pub(crate) fn put_folder_in_place(
    from: &Path,
    to: &Path,
    replace: bool,
) -> std::io::Result<Option<PathBuf>> {
    let mut files = temp_files();
    let old = if replace {
        let old = temp_name(to, "old", random_suffix());
        std::fs::rename(to, &old)?;
        if let Err(e) = std::fs::rename(from, to) {
            let _ = std::fs::rename(&old, to);
            return Err(e);
        }
        files.push(Temp::Folder(old.clone()));
        Some(old)
    } else {
        std::fs::rename(from, to)?;
        None
    };
    files.retain(|t| t.path() != from);
    Ok(old)
}

/// Removes every temporary file and folder in the making and keeps the registry locked, so that
/// no new one is started and none is renamed into place: call it only right before exiting (the
/// binary does on SIGINT/SIGTERM).
pub fn remove_temp_files() {
    let files = temp_files();
    for f in files.iter() {
        f.remove();
    }
    std::mem::forget(files);
}

/// Ends the registered temporary file `tmp`, whose writing gave `written`: renamed over `path`
/// when it was written whole, else (or when the rename fails) removed; either way dropped from
/// the registry, under the registry's lock, so a signal's cleanup comes before or after.
pub(super) fn put_file_in_place<T>(
    tmp: &Path,
    path: &Path,
    written: std::io::Result<T>,
) -> std::io::Result<()> {
    let mut files = temp_files();
    let result = written.and_then(|_| std::fs::rename(tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(tmp);
    }
    files.retain(|t| t.path() != tmp);
    result
}
