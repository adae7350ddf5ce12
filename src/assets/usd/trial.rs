//! A trial read in a child process. openusd sizes some buffers by counts
//! the file declares (binary USD's sections and arrays) and allocates them
//! before reading: a hostile file can ask for more memory than the machine
//! has, and a failed allocation aborts the process, which `catch_unwind`
//! cannot catch. So the file is first read in a forked child, with the
//! address space limited to the memory budget; only when the child ends
//! normally is it read again here. A child killed by a signal (an abort
//! on a failed allocation, a crash) makes the file an error. The child
//! never returns into the caller: it ends with `_exit`.

/// Runs `f` in a child process; Err where the child did not end normally.
#[cfg(unix)]
pub(super) fn survives(budget: u64, f: impl FnOnce()) -> Result<(), String> {
    // SAFETY: the child only runs `f` (the read, which takes no lock that
    // another thread of the parent may hold: glibc's allocator is
    // prepared for fork) and then `_exit`, without unwinding into the
    // parent's frames; the parent only waits for it.
    let pid = unsafe { libc::fork() };
    if pid < 0 {
        // No child to be had: read in this process, as without the trial.
        return Ok(());
    }
    if pid == 0 {
        // SAFETY: setrlimit and signal with valid arguments, then _exit;
        // a panic is caught and becomes exit status 0 (the parent's read
        // will meet it again and report it).
        unsafe {
            let limit = libc::rlimit {
                rlim_cur: budget.saturating_add(1 << 30),
                rlim_max: libc::RLIM_INFINITY,
            };
            libc::setrlimit(libc::RLIMIT_AS, &limit);
            for sig in [
                libc::SIGABRT,
                libc::SIGSEGV,
                libc::SIGBUS,
                libc::SIGILL,
                libc::SIGFPE,
            ] {
                libc::signal(sig, libc::SIG_DFL);
            }
        }
        std::panic::set_hook(Box::new(|_| {}));
        let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_ok();
        // SAFETY: ends the child without running the parent's destructors.
        unsafe { libc::_exit(if ok { 0 } else { 3 }) };
    }
    let mut status = 0;
    // SAFETY: waits for our own child.
    let waited = unsafe { libc::waitpid(pid, &mut status, 0) };
    if waited != pid {
        return Ok(());
    }
    if libc::WIFEXITED(status) {
        return Ok(());
    }
    Err(format!(
        "the USD reader was stopped by signal {} on this file (it asks for more memory than the budget, or the reader crashed)",
        libc::WTERMSIG(status)
    ))
}

/// Without fork: read in this process.
#[cfg(not(unix))]
pub(super) fn survives(_budget: u64, _f: impl FnOnce()) -> Result<(), String> {
    Ok(())
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A read that ends normally passes, a panic too (the parent meets it
    /// again); one whose allocation the machine refuses (here: beyond the
    /// child's address-space limit) aborts the child and is an error.
    #[test]
    fn an_abort_in_the_child_is_an_error_not_the_end_of_the_process() {
        assert!(survives(1 << 30, || {}).is_ok());
        assert!(survives(1 << 30, || panic!("caught")).is_ok());
        let e = survives(1 << 30, || {
            let v = vec![1u8; 1 << 40];
            std::hint::black_box(&v);
        })
        .unwrap_err();
        assert!(e.contains("stopped by signal"), "{e}");
    }
}
