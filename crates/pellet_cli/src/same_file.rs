//! Refusing an output that is one of the inputs (writing it would replace the input: outputs
//! are renamed into place) and two outputs that are one file (the last written would replace
//! the other, or both would mix on stdout). The checks run before anything is read or written.

use std::path::{Path, PathBuf};

/// Errors when two outputs (`(flag, path)`) name the same file or both stdout (`-`), and
/// then as [`refuse_overwriting_inputs`] does. Paths are compared as files: `./x`,
/// `dir/../x` and a symbolic link to `x` are `x`, also when `x` does not exist yet. The null
/// device is no clash: both outputs are meant to be discarded.
pub fn refuse_clashing_outputs<I, O>(inputs: I, outputs: O) -> anyhow::Result<()>
where
    I: IntoIterator,
    I::Item: AsRef<str>,
    O: IntoIterator<Item = (String, String)>,
{
    let outputs: Vec<(String, String)> = outputs.into_iter().collect();
    let targets: Vec<Option<Target>> = outputs.iter().map(|(_, path)| target(path)).collect();
    for (i, a) in targets.iter().enumerate() {
        let Some(a) = a else { continue };
        let Some(j) = targets[..i].iter().position(|b| b.as_ref().is_some_and(|b| b.same_as(a))) else { continue };
        let ((first, first_path), (second, second_path)) = (&outputs[j], &outputs[i]);
        let clash = if first_path != second_path {
            format!("{first} {first_path} and {second} {second_path} are the same file")
        } else if first == second {
            format!("{first} names {} twice", shown(first_path))
        } else {
            format!("{first} and {second} both name {}", shown(first_path))
        };
        anyhow::bail!("{clash}; give each output its own file");
    }
    refuse_overwriting_inputs(inputs, outputs)
}

fn shown(path: &str) -> String {
    if path == "-" {
        "- (stdout)".to_string()
    } else {
        path.to_string()
    }
}

/// Where an output goes, as far as the file system says before anything is written.
enum Target {
    Stdout,
    /// The canonical path (for a file not there yet, its directory's, plus its name) and,
    /// for an existing file, its identity (a hard link is the same file by another path).
    File(PathBuf, Option<FileId>),
}

impl Target {
    fn same_as(&self, other: &Target) -> bool {
        match (self, other) {
            (Target::Stdout, Target::Stdout) => true,
            (Target::File(a, ida), Target::File(b, idb)) => a == b || (ida.is_some() && ida == idb),
            _ => false,
        }
    }
}

/// `None` for the null device, which any number of outputs may share.
fn target(path: &str) -> Option<Target> {
    if path == "-" {
        return Some(Target::Stdout);
    }
    // A path whose directory does not exist either: compared as written (writing it fails).
    let canonical = canonical(Path::new(path)).unwrap_or_else(|| PathBuf::from(path));
    if canonical == Path::new("/dev/null") {
        return None;
    }
    Some(Target::File(canonical, file_id(path)))
}

/// Errors when any output (`(flag, path)`) names the same existing regular file as one of
/// the inputs, by the same path or through another path, a hard link or a symbolic link.
/// `-` (stdin, stdout) and special files (devices, FIFOs) are never the same file here.
pub fn refuse_overwriting_inputs<I, O>(inputs: I, outputs: O) -> anyhow::Result<()>
where
    I: IntoIterator,
    I::Item: AsRef<str>,
    O: IntoIterator<Item = (String, String)>,
{
    let inputs: Vec<(String, FileId)> = inputs
        .into_iter()
        .filter_map(|p| {
            let p = p.as_ref();
            file_id(p).map(|id| (p.to_string(), id))
        })
        .collect();
    for (flag, path) in outputs {
        let Some(id) = file_id(&path) else { continue };
        if let Some((input, _)) = inputs.iter().find(|(_, i)| *i == id) {
            let via = if *input == path { String::new() } else { format!(" ({path} is {input})") };
            anyhow::bail!(
                "{flag} {path} is the input {input}{via}: writing it would destroy the input; give {flag} another file"
            );
        }
    }
    Ok(())
}

/// The canonical path of `path`, which need not exist: its canonical directory plus its name,
/// after following symbolic links (also one to a file not there yet).
fn canonical(path: &Path) -> Option<PathBuf> {
    let mut p = path.to_path_buf();
    // As many links as the kernel follows before it gives up on a loop.
    for _ in 0..40 {
        if let Ok(c) = std::fs::canonicalize(&p) {
            return Some(c);
        }
        match std::fs::read_link(&p) {
            // A relative link is relative to its own directory; an absolute one replaces it.
            Ok(to) => p = p.parent().map_or_else(|| to.clone(), |dir| dir.join(&to)),
            Err(_) => {
                let name = p.file_name()?;
                let dir = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
                return Some(std::fs::canonicalize(dir).ok()?.join(name));
            }
        }
    }
    None
}

#[cfg(unix)]
type FileId = (u64, u64);
#[cfg(not(unix))]
type FileId = std::path::PathBuf;

/// The identity of an existing regular file (links followed), or `None`.
fn file_id(path: &str) -> Option<FileId> {
    if path == "-" {
        return None;
    }
    let meta = std::fs::metadata(Path::new(path)).ok().filter(std::fs::Metadata::is_file)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some((meta.dev(), meta.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        std::fs::canonicalize(path).ok()
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::{refuse_clashing_outputs, refuse_overwriting_inputs};

    fn out(flag: &str, path: &std::path::Path) -> (String, String) {
        (flag.to_string(), path.display().to_string())
    }

    #[test]
    fn the_same_file_by_any_name_is_refused_and_others_pass() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("a.packing");
        std::fs::write(&input, b"x").unwrap();
        let hard = dir.path().join("hard");
        std::fs::hard_link(&input, &hard).unwrap();
        let soft = dir.path().join("soft");
        std::os::unix::fs::symlink(&input, &soft).unwrap();
        let other = dir.path().join("b.csv");
        std::fs::write(&other, b"y").unwrap();
        let inputs = [input.display().to_string()];
        let dotted = dir.path().join(".").join("a.packing");
        for same in [&input, &hard, &soft, &dotted] {
            let e = refuse_overwriting_inputs(&inputs, [out("-o", same)]).unwrap_err().to_string();
            assert!(e.contains("would destroy the input") && e.starts_with("-o "), "{e}");
        }
        let missing = dir.path().join("new.csv");
        refuse_overwriting_inputs(&inputs, [out("-o", &other), out("--csv", &missing), ("-o".into(), "-".into())])
            .unwrap();
        refuse_overwriting_inputs(["-"], [out("-o", &input)]).unwrap();
    }

    #[test]
    fn two_outputs_naming_one_file_by_any_spelling_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let existing = dir.path().join("x");
        std::fs::write(&existing, b"x").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&existing, &link).unwrap();
        let new = dir.path().join("new.csv");
        let refused = |a: std::path::PathBuf, b: std::path::PathBuf| {
            refuse_clashing_outputs(["in"], [out("-o", &a), out("--csv", &b)]).unwrap_err().to_string()
        };
        // Existing and not yet existing files, through `.`, `..` and a symbolic link.
        for target in [&existing, &new] {
            let name = target.file_name().unwrap();
            let e = refused(target.clone(), target.clone());
            assert!(e.starts_with("-o and --csv both name ") && e.ends_with("; give each output its own file"), "{e}");
            let e = refused(target.clone(), dir.path().join(".").join(name));
            assert!(e.contains(" are the same file; give each output its own file"), "{e}");
            refused(sub.join("..").join(name), target.clone());
        }
        refused(existing.clone(), link.clone());
        let dangling = dir.path().join("dangling");
        std::os::unix::fs::symlink("sub/later.csv", &dangling).unwrap();
        refused(dangling, sub.join("later.csv"));
        let e = refuse_clashing_outputs(["in"], [("-o".into(), "-".into()), ("--csv".into(), "-".into())])
            .unwrap_err()
            .to_string();
        assert_eq!(e, "-o and --csv both name - (stdout); give each output its own file");
        let e = refuse_clashing_outputs(["in"], [out("--plot", &new), out("--plot", &new)]).unwrap_err().to_string();
        assert!(e.starts_with("--plot names ") && e.contains(" twice;"), "{e}");
        // Different files, stdout and a file, and the null device twice are no clash.
        refuse_clashing_outputs(
            ["in"],
            [
                out("-o", &existing),
                out("--csv", &new),
                ("--axial".into(), "-".into()),
                out("--summary", &sub.join("x")),
            ],
        )
        .unwrap();
        refuse_clashing_outputs(["in"], [("-o".into(), "/dev/null".into()), ("--csv".into(), "/dev/null".into())])
            .unwrap();
        // Inputs are still checked.
        let inputs = [existing.display().to_string()];
        assert!(refuse_clashing_outputs(&inputs, [out("-o", &new), out("--csv", &link)]).is_err());
    }
}
