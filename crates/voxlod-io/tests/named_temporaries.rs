//! Named temporaries (the fallback where a file system has no unnamed ones, or asked for with
//! `atomic::use_named_temporaries`) are removed when SIGINT or SIGTERM stops the process, which
//! then ends with 130 or 143 and the message; what was in the folder before stays, and a folder
//! the unfinished set created goes.
//!
//! A harness of its own (`harness = false`): the test runs its own executable as the child that
//! is stopped, and that child must be a process whose every thread blocks the signals, as a
//! `main` that calls `remove_temporaries_on_signals` first thing is. Under libtest the main
//! thread would not block them, and a signal would end the child before any clean-up.

#[cfg(unix)]
fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    if let Some(out) = std::env::var_os(CHILD) {
        child(std::path::Path::new(&out));
    }
    for (signal, name, code) in [
        (libc::SIGINT, "SIGINT", 130),
        (libc::SIGTERM, "SIGTERM", 143),
    ] {
        for existing in [true, false] {
            stop_a_writer(signal, name, code, existing);
        }
    }
    println!("test named_temporaries_are_removed_on_sigint_and_sigterm ... ok");
}

#[cfg(not(unix))]
fn main() {}

/// The variable that makes the executable the child, naming its output folder.
#[cfg(unix)]
const CHILD: &str = "VOXLOD_TEST_NAMED_TEMPORARIES_CHILD";

/// The child: makes `OUT` where it is missing, stages `OUT/level-0.ply` through a named
/// temporary, says so on standard output, and waits to be stopped.
#[cfg(unix)]
fn child(out: &std::path::Path) -> ! {
    use voxlod_io::atomic::{remove_temporaries_on_signals, use_named_temporaries};
    remove_temporaries_on_signals("stopped");
    use_named_temporaries();
    let mut set = voxlod_io::OutputSet::new();
    set.create_dir(out).expect("the child makes its folder");
    set.bytes(&out.join("level-0.ply"), b"ply\n")
        .expect("the child stages its file");
    println!("staged");
    loop {
        std::thread::sleep(std::time::Duration::from_secs(1));
    }
}

/// Runs the child into `out` (made beforehand, holding `notes.txt`, when `existing`), sends
/// `signal` once its temporary shows, and checks how it ended and what it left.
#[cfg(unix)]
fn stop_a_writer(signal: libc::c_int, name: &str, code: i32, existing: bool) {
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};
    use voxlod_testkit::files::entries as names;

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    if existing {
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
    }
    let mut child = Command::new(std::env::current_exe().unwrap())
        .env(CHILD, &out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    stdout.read_line(&mut line).unwrap();
    if line != "staged\n" {
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        panic!(
            "{name}: the child did not stage its file ({}): {err}",
            o.status
        );
    }
    let temporaries: Vec<String> = names(&out)
        .into_iter()
        .filter(|n| n.starts_with(".level-0.ply.tmp-"))
        .collect();
    assert_eq!(temporaries.len(), 1, "{name}: {:?}", names(&out));
    // SAFETY: kill takes a process id and a signal number; the child is ours and still running.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "{name}: {err}");
    assert!(
        err.contains("stopped") && err.contains(name),
        "{name}: {err}"
    );
    if existing {
        assert_eq!(names(&out), ["notes.txt"], "{name}");
    } else {
        assert!(!out.exists(), "{name}: {:?} left", names(&out));
    }
}
