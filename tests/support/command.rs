//! Running the `slipgate` command from an end-to-end test, and where such a test keeps its files.

use std::path::PathBuf;
use std::process::{Command, Output};

pub fn slipgate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_slipgate"))
        .args(args)
        .output()
        .expect("run slipgate")
}

/// `name` in a temporary directory of test binary `test`'s own (per process).
pub fn scratch(test: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}
