//! Writing output files atomically: every file a command writes goes through a temporary file
//! beside it (a distinct name, made by `tempfile`), flushed to disk, then renamed over the
//! target, so the target is either the complete new file or untouched. On any error the
//! temporary file is removed (it is deleted when dropped unless renamed).
//!
//! Errors name the *target* path, never the temporary one. Files get the usual permissions
//! (0666 less the umask, as any program's new files), not `tempfile`'s private 0600.
//!
//! **Interrupts.** A temporary file is removed when dropped, which a killed process never does:
//! both binaries install a Ctrl-C handler (`ctrlc`) in `main` that calls
//! [`remove_temporaries`] (every temporary file still being written is deleted), then exits with
//! status 130.
//!
//! **Inputs are never outputs.** [`refuse_inputs`] compares an output path with every input
//! file of the command by canonical path (the output's folder canonicalized, as the output
//! itself may not exist yet), so `fit --out` one of its own recordings is refused before
//! anything is written.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files being written right now (removed on Ctrl-C).
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn track(p: &Path) {
    if let Ok(mut v) = LIVE.lock() {
        v.push(p.to_path_buf());
    }
}

fn untrack(p: &Path) {
    if let Ok(mut v) = LIVE.lock() {
        v.retain(|x| x != p);
    }
}

/// Removes every temporary file still being written (for an interrupt handler: see the module
/// docs).
pub fn remove_temporaries() {
    if let Ok(v) = LIVE.lock() {
        for p in v.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// A new temporary file in `dir` named `.{name}.XXXXXX.tmp`, with the usual permissions.
fn temporary(dir: &Path, name: &std::ffi::OsStr) -> std::io::Result<tempfile::NamedTempFile> {
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let t = b.tempfile_in(dir)?;
    track(t.path());
    Ok(t)
}

/// `path` made absolute and canonical as far as it exists: its folder canonicalized and its
/// file name appended (`None` if the folder does not exist).
pub fn canonical_target(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(dir.canonicalize().ok()?.join(path.file_name()?))
}

/// An output that is also an input.
#[derive(Debug, thiserror::Error)]
#[error("{}: this output is also an input ({}); choose another output path", output.display(), input.display())]
pub struct OverwriteError {
    /// The output as given.
    pub output: PathBuf,
    /// The input it is.
    pub input: PathBuf,
}

/// Refuses when any of `outputs` is the same file as any of `inputs` (see the module docs).
pub fn refuse_inputs(outputs: &[&Path], inputs: &[&Path]) -> Result<(), OverwriteError> {
    let ins: Vec<(PathBuf, &Path)> = inputs
        .iter()
        .filter_map(|p| Some((p.canonicalize().ok()?, *p)))
        .collect();
    for out in outputs {
        let Some(c) = canonical_target(out) else {
            continue;
        };
        if let Some((_, input)) = ins.iter().find(|(i, _)| *i == c) {
            return Err(OverwriteError {
                output: out.to_path_buf(),
                input: input.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Writing `path` failed.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write: {source}", path.display())]
pub struct OutputError {
    /// The file that was to be written.
    pub path: PathBuf,
    /// The cause.
    pub source: std::io::Error,
}

/// Writes `bytes` to `path` atomically (see the module docs).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// Creates a temporary file beside `path`, lets `write` fill it, flushes it to disk and
/// renames it over `path`. `write` gets the open file (and may also reopen it by its path,
/// `f.path()`).
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut tempfile::NamedTempFile) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    let err = |source| OutputError {
        path: path.to_path_buf(),
        source: plain(source),
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| err(std::io::Error::other("not a file name")))?;
    let mut tmp = temporary(dir, name).map_err(err)?;
    let tmp_path = tmp.path().to_path_buf();
    let written = write(&mut tmp)
        .and_then(|()| tmp.as_file_mut().flush())
        .and_then(|()| tmp.as_file().sync_all());
    if let Err(e) = written {
        drop(tmp);
        untrack(&tmp_path);
        return Err(err(e));
    }
    let persisted = tmp.persist(path);
    untrack(&tmp_path);
    persisted.map_err(|e| err(e.error))?;
    Ok(())
}

/// Writes `files` (name, bytes) into `dir` (created if needed) all or nothing: every file first
/// to its own temporary sibling, then all renamed. On a failure the temporaries are removed and
/// the targets renamed so far are deleted, so no partial set of outputs is left. Returns the
/// paths written.
pub fn write_all_atomic(
    dir: &Path,
    files: &[(&str, Vec<u8>)],
) -> Result<Vec<PathBuf>, OutputError> {
    let err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| OutputError {
            path,
            source: plain(source),
        }
    };
    std::fs::create_dir_all(dir).map_err(err(dir))?;
    let mut temps = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        let target = dir.join(name);
        let mut tmp = match temporary(dir, std::ffi::OsStr::new(name)) {
            Ok(t) => t,
            Err(e) => {
                temps
                    .iter()
                    .for_each(|(t, _): &(tempfile::NamedTempFile, PathBuf)| untrack(t.path()));
                return Err(err(&target)(e));
            }
        };
        if let Err(e) = tmp
            .as_file_mut()
            .write_all(bytes)
            .and_then(|()| tmp.as_file().sync_all())
        {
            untrack(tmp.path());
            temps.iter().for_each(|(t, _)| untrack(t.path()));
            return Err(err(&target)(e));
        }
        temps.push((tmp, target));
    }
    let mut done: Vec<PathBuf> = Vec::with_capacity(temps.len());
    let paths: Vec<PathBuf> = temps.iter().map(|(t, _)| t.path().to_path_buf()).collect();
    let untrack_all = || paths.iter().for_each(|p| untrack(p));
    for (tmp, target) in temps {
        if let Err(e) = tmp.persist(&target) {
            untrack_all();
            for d in &done {
                let _ = std::fs::remove_file(d);
            }
            return Err(err(&target)(e.error));
        }
        done.push(target);
    }
    untrack_all();
    Ok(done)
}

/// The operating system's error without the temporary file's path (which `tempfile` appends
/// as " at path ..."): messages name the target only.
fn plain(e: std::io::Error) -> std::io::Error {
    let text = e.to_string();
    match text.find(" at path ") {
        Some(i) => std::io::Error::new(e.kind(), text[..i].to_string()),
        None => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_replace_the_file_and_leave_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_removes_the_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.bin");
        write_atomic(&p, b"old").unwrap();
        let e = write_atomic_with(&p, |_| Err(std::io::Error::other("disk full"))).unwrap_err();
        assert!(e.to_string().starts_with(&p.display().to_string()), "{e}");
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_set_of_files_is_written_whole() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let files = [("a.txt", b"a".to_vec()), ("b.txt", b"bb".to_vec())];
        let written = write_all_atomic(&out, &files).unwrap();
        assert_eq!(written.len(), 2);
        assert_eq!(std::fs::read(out.join("b.txt")).unwrap(), b"bb");
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
        // A name that cannot be a file (a folder is in the way): nothing new is left.
        std::fs::create_dir(out.join("c.txt")).unwrap();
        let files = [("d.txt", b"d".to_vec()), ("c.txt", b"c".to_vec())];
        let e = write_all_atomic(&out, &files).unwrap_err();
        assert!(e.to_string().contains("c.txt"), "{e}");
        assert!(!out.join("d.txt").exists());
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 3);
    }

    #[test]
    fn an_output_in_a_missing_folder_names_the_output() {
        let p = Path::new("/nonexistent-folder-for-a-test/x.json");
        let e = write_atomic(p, b"{}").unwrap_err();
        assert!(
            e.to_string()
                .contains("/nonexistent-folder-for-a-test/x.json"),
            "{e}"
        );
        assert!(!e.to_string().contains(".tmp"), "{e}");
    }
}
