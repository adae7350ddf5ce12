//! The `softraster` binary under test.

/// Its path, built by cargo for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_softraster");

/// Runs the binary: exit status, stdout, stderr.
pub fn run(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(BIN).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
