//! Running a third-party reader that may panic on a damaged file
//! (openusd, the Basis Universal transcoder): the panic becomes an error
//! for the caller, and its message and backtrace are not printed (the
//! caller reports the file's error instead).

use std::cell::Cell;
use std::sync::Once;

thread_local! {
    /// Whether this thread is inside `catch` (its panics are expected).
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`; None where it panicked. Panics of other threads, and of this
/// one outside `catch`, print as before.
pub fn catch<T>(f: impl FnOnce() -> T) -> Option<T> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let before = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                before(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    r.ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_is_an_error() {
        assert_eq!(catch(|| 3), Some(3));
        assert_eq!(catch(|| -> i32 { panic!("damaged") }), None);
        // Nested: the inner catch leaves this thread quiet for the outer.
        assert_eq!(catch(|| catch(|| 1).map(|v| v + 1)), Some(Some(2)));
    }
}
