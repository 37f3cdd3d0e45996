//! Tests that cannot run here, counted rather than passed off as run.
//!
//! A test that needs something a fresh clone may lack (the shared real data, the peers' glTF
//! validator, a file system with unnamed temporary files) calls [`skip`] and returns. libtest
//! captures what a passing test prints, so the reason alone would never be seen: [`skip`] also
//! appends one line to the file named by `VOXLOD_SKIP_LOG` when that is set. `scripts/test` (the
//! README's and CI's test command) points it at `skipped-tests.tsv` in the target folder, runs
//! `cargo test --workspace --release` and ends with how many tests skipped and why.
//!
//! A line is four tab-separated fields: the package, the test target (the test file's or
//! crate's name), the test (libtest names each test's thread after it) and the reason. A test
//! that skips several inputs writes several lines; the summary counts it once. Other test
//! runners (Python, browser) may append lines of the same form.

use std::fmt::Display;
use std::io::Write;
use std::path::Path;

/// The environment variable naming the file that skips are appended to.
pub const LOG_VARIABLE: &str = "VOXLOD_SKIP_LOG";

/// Records that the calling test skips (all or part of its work) for `reason`: printed to
/// stderr (seen with `--nocapture`), and appended to the `VOXLOD_SKIP_LOG` file when set.
///
/// # Panics
///
/// When `VOXLOD_SKIP_LOG` is set but the line cannot be appended: a skip that is not counted
/// would make the summary lie.
pub fn skip(reason: impl Display) {
    skip_as("", reason);
}

/// [`skip`], naming the caller `label` where it is not a libtest test (an example, a bench).
pub fn skip_as(label: &str, reason: impl Display) {
    let test = current_test(label);
    let reason = reason.to_string();
    eprintln!("skipping {test}: {reason}");
    if let Some(log) = std::env::var_os(LOG_VARIABLE) {
        let package = std::env::var("CARGO_PKG_NAME").unwrap_or_else(|_| "?".into());
        let line = log_line(&[&package, &test_target(), &test, &reason]);
        if let Err(err) = append(Path::new(&log), &line) {
            panic!(
                "cannot record a skipped test in {LOG_VARIABLE}={}: {err}",
                Path::new(&log).display()
            );
        }
    }
}

/// Appends `line` in one write in append mode, so that parallel tests never interleave lines.
fn append(log: &Path, line: &str) -> std::io::Result<()> {
    std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(log)?
        .write_all(line.as_bytes())
}

/// One line of the log: the fields separated by tabs (tabs and line breaks inside a field become
/// spaces), ending in a line break.
fn log_line(fields: &[&str]) -> String {
    let fields: Vec<String> = fields
        .iter()
        .map(|f| f.replace(['\t', '\n', '\r'], " "))
        .collect();
    fields.join("\t") + "\n"
}

/// The running test's name: libtest runs each test on a thread named after it; elsewhere (an
/// example, a bench) `label`, or the executable's name.
fn current_test(label: &str) -> String {
    match std::thread::current().name() {
        Some(name) if name != "main" => name.to_string(),
        _ if !label.is_empty() => label.to_string(),
        _ => test_target(),
    }
}

/// The test target: the executable's name without the hash cargo appends (`real_data-1f2e…`).
fn test_target() -> String {
    let exe = std::env::current_exe().unwrap_or_default();
    let stem = exe
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    match stem.rsplit_once('-') {
        Some((name, hash)) if hash.chars().all(|c| c.is_ascii_hexdigit()) => name.to_string(),
        _ => stem,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_test_is_named_after_its_thread_and_its_target() {
        let name = "skips::tests::a_test_is_named_after_its_thread_and_its_target";
        assert_eq!(current_test("label"), name);
        assert_eq!(test_target(), "voxlod_testkit");
        let from_main = std::thread::Builder::new()
            .name("main".into())
            .spawn(|| (current_test("an example"), current_test("")))
            .unwrap()
            .join()
            .unwrap();
        assert_eq!(from_main, ("an example".into(), "voxlod_testkit".into()));
    }

    #[test]
    fn lines_are_appended_whole_with_clean_fields() {
        let log = std::env::temp_dir().join(format!("voxlod-skips-{}.tsv", std::process::id()));
        let _ = std::fs::remove_file(&log);
        append(&log, &log_line(&["p", "t", "a\ttest", "no\ndata"])).unwrap();
        append(&log, &log_line(&["p", "t", "b", "c"])).unwrap();
        let text = std::fs::read_to_string(&log).unwrap();
        std::fs::remove_file(&log).unwrap();
        assert_eq!(text, "p\tt\ta test\tno data\np\tt\tb\tc\n");
    }
}
