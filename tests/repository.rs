//! The repository speaks to its users about the software: no development diary in code,
//! docs or tool output (the words of one below). Design decisions and rejected alternatives
//! are in the design docs by topic (docs/engine.md, docs/validation/reproducing.md).

use std::path::{Path, PathBuf};

fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if path.is_dir() {
            text_files(&path, out);
        } else {
            let text = matches!(path.extension().and_then(|e| e.to_str()), Some("rs" | "md" | "mk" | "sh" | "toml"))
                || name == "Makefile";
            if text {
                out.push(path);
            }
        }
    }
}

/// Whether `line` holds "issue" or "issues" followed by a number (after a space, `_` or `#`,
/// as in a test's name).
fn cites_an_issue(line: &str) -> bool {
    let lower = line.to_lowercase();
    let word = concat!("iss", "ue");
    lower.match_indices(word).any(|(at, _)| {
        let rest = lower[at + word.len()..].trim_start_matches('s');
        let rest = rest.strip_prefix([' ', '_']).unwrap_or(rest);
        rest.trim_start_matches('#').starts_with(|c: char| c.is_ascii_digit())
    })
}

#[test]
fn no_development_diary_in_the_tree() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    assert!(files.len() > 50, "found only {} files under {}", files.len(), root.display());
    // The diary's words, and the names of the logs that were folded into the design docs.
    let banned =
        [concat!("ses", "sion"), concat!("physics", ".md"), concat!("no", "tes.md"), concat!("paper-study", "-log")];
    let mut found = Vec::new();
    for path in &files {
        let Ok(text) = std::fs::read_to_string(path) else { continue };
        for (n, line) in text.lines().enumerate() {
            let lower = line.to_lowercase();
            let hit = banned.iter().any(|w| lower.contains(w));
            if hit || cites_an_issue(line) {
                found.push(format!("{}:{}: {}", path.strip_prefix(&root).unwrap().display(), n + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "diary words in the tree:\n{}", found.join("\n"));
}

#[test]
fn issue_citations_are_recognised() {
    assert!(cites_an_issue(concat!("see iss", "ue 8")));
    assert!(cites_an_issue(concat!("(iss", "ues 3 and 4)")));
    assert!(cites_an_issue(concat!("fn iss", "ue_8_the_pipeline()")));
    assert!(cites_an_issue(concat!("iss", "ue #12")));
    assert!(!cites_an_issue("an issue of the mesh"));
}
