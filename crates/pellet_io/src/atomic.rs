//! Reading inputs and writing outputs: `-` for stdin/stdout, atomic files.

use std::io::{IsTerminal, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::IoError;

/// The temporary files being written, removed by the signal handler (a temporary file is
/// otherwise removed only when its writer returns, and an interrupted tool never returns), and
/// whether they are being renamed into place.
static TEMPORARIES: Mutex<Staging> = Mutex::new(Staging { paths: Vec::new(), committing: false, written: false });

struct Staging {
    paths: Vec<PathBuf>,
    committing: bool,
    /// Some outputs are in place: an interrupt no longer leaves every output as it was.
    written: bool,
}

/// On Ctrl-C or SIGTERM, removes the temporary files of [`write_outputs`] in progress (the
/// outputs stay as they were) and ends the tool with `tool: error: interrupted` and exit 2.
/// Once the complete outputs are being renamed into place, the signal lets the renames finish
/// and the tool end as it would have: stopping between two renames would leave some outputs
/// new and others old. For tools that install no handler of their own (`pack` finishes its
/// step and keeps its run).
pub fn remove_temporary_files_on_signal(tool: &'static str) {
    let _ = ctrlc::set_handler(move || {
        // Held to the exit, so that no rename can start after the temporaries are gone.
        let Ok(mut staging) = TEMPORARIES.lock() else { std::process::exit(2) };
        if staging.committing {
            return;
        }
        remove_temporaries(&mut staging);
        if staging.written {
            eprintln!("{tool}: error: interrupted after writing some of its outputs");
        } else {
            eprintln!("{tool}: error: interrupted; no output was changed");
        }
        std::process::exit(2);
    });
}

fn remove_temporaries(staging: &mut Staging) {
    for path in std::mem::take(&mut staging.paths) {
        let _ = std::fs::remove_file(path);
    }
}

fn registered(path: &Path, add: bool) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        if add {
            t.paths.push(path.to_path_buf());
        } else {
            t.paths.retain(|p| p != path);
        }
    }
}

/// Marks the renames into place as begun (`true`: from here the outputs are complete) or
/// ended.
fn committing(now: bool) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        t.committing = now;
        t.written |= !now;
    }
}

/// One output: a destination (`-` = stdout) and its bytes.
pub struct OutputFile {
    /// Path, or `-` for stdout.
    pub path: String,
    /// The complete contents.
    pub bytes: Vec<u8>,
    /// Whether the contents are binary (refused on a terminal).
    pub binary: bool,
    /// What it is, for messages (e.g. "pellet file").
    pub what: String,
}

/// Reads a whole input file, or stdin for `-` (refused when stdin is a terminal).
pub fn read_input(path: &str) -> Result<Vec<u8>, IoError> {
    if path == "-" {
        let stdin = std::io::stdin();
        if stdin.is_terminal() {
            return Err(IoError::Io {
                path: "-".into(),
                source: std::io::Error::other("stdin is a terminal; give a file name or pipe the data in"),
            });
        }
        let mut buf = Vec::new();
        stdin.lock().read_to_end(&mut buf).map_err(|source| IoError::Io { path: "-".into(), source })?;
        return Ok(buf);
    }
    std::fs::read(path).map_err(|source| IoError::Io { path: path.into(), source })
}

/// Whether `path` names an existing file that is neither a regular file nor a directory (a
/// device such as `/dev/null` or `/dev/stdout`, a FIFO, a socket). Such a target must be
/// written in place: renaming a finished temporary file onto it would replace it (as root,
/// `-o /dev/null` replaced the null device with a regular file, and every later reader of
/// /dev/null got the last bytes written there).
pub fn is_special_file(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Writes every output, all or nothing as far as the file system allows:
/// each is first written in full to a temporary file beside its target,
/// and only when all are complete are they renamed into place. Special
/// files (devices, FIFOs: [`is_special_file`]) are written in place after
/// that, and stdout (`-`) last. An output to a stdout that was closed at start is refused
/// before anything is written.
pub fn write_outputs(outputs: &[OutputFile]) -> Result<(), IoError> {
    if outputs.iter().any(|o| o.path == "-") {
        crate::require_stdout()?;
    }
    let (in_place, renamed): (Vec<&OutputFile>, Vec<&OutputFile>) =
        outputs.iter().filter(|o| o.path != "-").partition(|o| is_special_file(Path::new(&o.path)));
    let mut staged = Vec::new();
    for out in renamed {
        let target = Path::new(&out.path);
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let io = |source| IoError::Io { path: out.path.clone(), source };
        // Checked first: the temporary file's error would name the temporary file instead.
        if !dir.is_dir() {
            let why = format!("the directory {} does not exist; create it or give another path", dir.display());
            return Err(io(std::io::Error::new(std::io::ErrorKind::NotFound, why)));
        }
        let mut builder = tempfile::Builder::new();
        builder.prefix(".packbed-").suffix(".tmp");
        // Temporary files are private (0600); an output is not: ask for
        // 0666 and let the umask decide, as for any file a tool creates.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        // tempfile's error names the temporary file, which the user never asked for.
        let mut tmp = builder.tempfile_in(dir).map_err(|e| io(std::io::Error::from(e.kind())))?;
        registered(tmp.path(), true);
        tmp.write_all(&out.bytes).map_err(io)?;
        tmp.as_file().sync_all().map_err(io)?;
        staged.push((tmp, target));
    }
    let staged_paths: Vec<PathBuf> = staged.iter().map(|(tmp, _)| tmp.path().to_path_buf()).collect();
    let renames = !staged.is_empty();
    if renames {
        committing(true);
    }
    let persisted = staged.into_iter().try_for_each(|(tmp, target)| {
        tmp.persist(target).map(|_| ()).map_err(|e| IoError::Io { path: target.display().to_string(), source: e.error })
    });
    staged_paths.iter().for_each(|p| registered(p, false));
    if renames {
        committing(false);
    }
    persisted?;
    for out in in_place {
        let io = |source| IoError::Io { path: out.path.clone(), source };
        let mut file = std::fs::OpenOptions::new().write(true).open(&out.path).map_err(io)?;
        file.write_all(&out.bytes).and_then(|_| file.flush()).map_err(io)?;
    }
    for out in outputs.iter().filter(|o| o.path == "-") {
        let stdout = std::io::stdout();
        if out.binary && stdout.is_terminal() {
            return Err(IoError::BinaryToTerminal { what: out.what.clone() });
        }
        let mut lock = stdout.lock();
        lock.write_all(&out.bytes)
            .and_then(|_| lock.flush())
            .map_err(|source| IoError::Io { path: "-".into(), source })?;
    }
    Ok(())
}

#[cfg(all(test, unix))]
mod tests {
    use std::os::unix::fs::{FileTypeExt, PermissionsExt};

    /// The temporaries are one list for the process: the test that empties it runs alone.
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

    fn serial() -> std::sync::MutexGuard<'static, ()> {
        SERIAL.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// An output that is a FIFO (or a device such as /dev/null) is written into, not replaced.
    #[test]
    fn a_fifo_output_is_written_in_place() {
        let _serial = serial();
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().expect("run mkfifo").success());
        let path = fifo.clone();
        let reader = std::thread::spawn(move || std::fs::read(path).unwrap());
        super::write_outputs(&[super::OutputFile {
            path: fifo.display().to_string(),
            bytes: b"abc".to_vec(),
            binary: false,
            what: "test".into(),
        }])
        .unwrap();
        // Checked before joining: had the FIFO been replaced, its reader would wait for ever.
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
        assert_eq!(reader.join().unwrap(), b"abc");
    }

    /// What the signal handler does: the temporary files in progress go, and nothing else.
    #[test]
    fn the_temporaries_in_progress_are_removed() {
        let _serial = serial();
        let dir = tempfile::tempdir().unwrap();
        let (tmp, kept) = (dir.path().join(".packbed-x.tmp"), dir.path().join("out.csv"));
        std::fs::write(&tmp, b"partial").unwrap();
        std::fs::write(&kept, b"old output").unwrap();
        super::registered(&tmp, true);
        super::remove_temporaries(&mut super::TEMPORARIES.lock().unwrap());
        assert!(!tmp.exists());
        assert_eq!(std::fs::read(&kept).unwrap(), b"old output");
    }

    #[test]
    fn outputs_get_the_permissions_of_any_new_file() {
        let _serial = serial();
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.bin").display().to_string();
        super::write_outputs(&[super::OutputFile {
            path: out.clone(),
            bytes: vec![1],
            binary: true,
            what: "test".into(),
        }])
        .unwrap();
        // A file made the ordinary way: 0666 less the umask.
        let reference = dir.path().join("reference");
        std::fs::File::create(&reference).unwrap();
        let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(std::path::Path::new(&out)), mode(&reference));
    }
}
