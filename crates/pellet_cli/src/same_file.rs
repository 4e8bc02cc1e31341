//! Refusing an output that is one of the inputs: writing it would replace the input (outputs
//! are renamed into place), so the check runs before anything is read or written.

use std::path::Path;

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
    use super::refuse_overwriting_inputs;

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
}
