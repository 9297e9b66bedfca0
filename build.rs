//! Names the commit `slipgate --version` reports: `git describe` of the source tree when it is a
//! git checkout (with `-dirty` for uncommitted changes), else what `SLIPGATE_COMMIT` says (a
//! package built from a tarball), else "unknown commit".

use std::process::Command;

fn main() {
    let commit = std::env::var("SLIPGATE_COMMIT").ok().or_else(|| {
        let out = Command::new("git")
            .args(["describe", "--always", "--dirty", "--abbrev=12"])
            .output()
            .ok()
            .filter(|o| o.status.success())?;
        Some(String::from_utf8_lossy(&out.stdout).trim().to_string())
    });
    let commit = commit.unwrap_or_else(|| "unknown commit".to_string());
    println!("cargo:rustc-env=SLIPGATE_COMMIT={commit}");
    println!("cargo:rerun-if-env-changed=SLIPGATE_COMMIT");
    // A new commit or a change to the index moves HEAD's description.
    for path in [
        ".git/HEAD",
        ".git/index",
        ".git/refs/heads",
        ".git/packed-refs",
    ] {
        println!("cargo:rerun-if-changed={path}");
    }
}
