//! Sets `PACKBED_BUILD`, the source a binary was built from: `git <commit>` (with `-dirty` when
//! files under `crates/`, `tools/` or the workspace manifests differ from that commit, new files
//! included), or `unknown` outside a git checkout. `pack` records
//! it in every trajectory, so an archived bed names the engine that made it.

use std::path::Path;
use std::process::Command;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let git_dir = root.join(".git");
    let build = if git_dir.exists() {
        // A commit moves logs/HEAD, an edit of a tracked file the sources (cargo scans the
        // directories), staging the index.
        for watched in [".git/HEAD", ".git/logs/HEAD", ".git/index", "crates", "tools", "Cargo.toml", "Cargo.lock"] {
            println!("cargo:rerun-if-changed={}", root.join(watched).display());
        }
        let git = |args: &[&str]| Command::new("git").arg("-C").arg(&root).args(args).output().ok();
        let commit = git(&["rev-parse", "--short=12", "HEAD"])
            .filter(|o| o.status.success())
            .and_then(|o| String::from_utf8(o.stdout).ok());
        // Dirty only where the binaries come from (edits of docs or bed records change no build),
        // counting files not yet added: a new module is compiled before it is committed.
        let dirty = git(&["status", "--porcelain", "--", "crates", "tools", "Cargo.toml", "Cargo.lock"])
            .is_some_and(|o| o.status.success() && !o.stdout.is_empty());
        match commit {
            Some(c) => format!("git {}{}", c.trim(), if dirty { "-dirty" } else { "" }),
            None => "unknown (git failed)".to_string(),
        }
    } else {
        println!("cargo:rerun-if-changed=build.rs");
        "unknown (not built from a git checkout)".to_string()
    };
    println!("cargo:rustc-env=PACKBED_BUILD={build}");
}
