//! Sets `PACKBED_BUILD`, the source a binary was built from: `git <commit>` (with `-dirty` when
//! tracked files differ from that commit), or `unknown` outside a git checkout. `pack` records
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
        Command::new("git")
            .arg("-C")
            .arg(&root)
            .args(["describe", "--always", "--dirty", "--abbrev=12", "--match", "NO-TAGS"])
            .output()
            .ok()
            .filter(|o| o.status.success())
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .map(|s| format!("git {}", s.trim()))
            .unwrap_or_else(|| "unknown (git describe failed)".to_string())
    } else {
        println!("cargo:rerun-if-changed=build.rs");
        "unknown (not built from a git checkout)".to_string()
    };
    println!("cargo:rustc-env=PACKBED_BUILD={build}");
}
