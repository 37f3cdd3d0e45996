//! Running a third-party parser so that a panic inside it becomes an error, silently.
//!
//! vtkio, ply-rs-bw and stl_io are fed arbitrary bytes, and a corrupt file can reach an
//! `unwrap` or an unchecked slice in them. [`quietly`] runs such a call under `catch_unwind`
//! with the panic message suppressed for that call only: a process-wide panic hook is installed
//! once, and it stays silent while a thread-local flag says that the current thread is inside
//! a guarded call. Other threads, and panics outside guarded calls, still print as before (the
//! hook that was installed before ours is called for them). The caller turns the caught panic
//! into an [`IoError`](crate::IoError) in its own words; the panic text is never shown.
//!
//! The guard needs unwinding: under `panic = "abort"` nothing can be caught, which is why the
//! readers also check what they can before calling a parser.
//!
//! Cost: one `catch_unwind` around each parser call, which costs nothing measurable when the
//! parser does not panic.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    static GUARDED: Cell<bool> = const { Cell::new(false) };
}

static INSTALL_HOOK: Once = Once::new();

fn install_hook() {
    INSTALL_HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !GUARDED.with(Cell::get) {
                previous(info);
            }
        }));
    });
}

/// Runs `f`; a panic inside it gives `None`, with nothing printed.
pub(crate) fn quietly<T>(f: impl FnOnce() -> T) -> Option<T> {
    install_hook();
    let outer = GUARDED.with(|g| g.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    GUARDED.with(|g| g.set(outer));
    result.ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_none_and_nesting_restores_the_flag() {
        assert_eq!(quietly(|| 7), Some(7));
        let caught: Option<()> = quietly(|| panic!("hidden"));
        assert!(caught.is_none());
        let nested = quietly(|| {
            let inner: Option<u8> = quietly(|| panic!("inner"));
            assert!(GUARDED.with(Cell::get), "the outer call is still guarded");
            inner
        });
        assert_eq!(nested, Some(None));
        assert!(!GUARDED.with(Cell::get));
        // Threads guard independently.
        let handles: Vec<_> = (0..4)
            .map(|i| std::thread::spawn(move || quietly(|| if i % 2 == 0 { panic!() } else { i })))
            .collect();
        let results: Vec<_> = handles.into_iter().map(|h| h.join().unwrap()).collect();
        assert_eq!(results, [None, Some(1), None, Some(3)]);
    }
}
