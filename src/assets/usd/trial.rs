//! A trial read in a child process. openusd sizes some buffers by counts
//! the file declares (binary USD's sections and arrays) and allocates them
//! before reading: a hostile file can ask for more memory than the machine
//! has, and a failed allocation aborts the process, which `catch_unwind`
//! cannot catch. So the file is first read in a forked child whose address
//! space may grow by the memory budget at most; only when the child ends
//! with status 0 is it read again here. A child that ends otherwise
//! (killed by a signal: an abort on a failed allocation, a crash; or
//! stopped by a sanitizer in fuzzing builds, which keep their huge address
//! space unlimited) makes the file an error. The child never returns into
//! the caller: it ends with `_exit`.
//!
//! The child also has a CPU-time limit (`cpu_seconds`): openusd loops
//! forever on some damaged text files (found by CI's fuzzing smoke,
//! 2026-11-28), and a farm must not wait on such a file for ever. Past the
//! limit the kernel stops the child (SIGXCPU) and the file is an error.

/// CPU seconds the trial read may take for a file of `bytes` bytes: 20,
/// and one more per 8 MiB (openusd reads well over 100 MiB a second).
/// A file the child reads within the limit is read once more here, so a
/// slow file costs at most twice the limit. Fuzzing builds allow 8 s:
/// libFuzzer gives one input 30 s in all.
fn cpu_seconds(bytes: usize) -> u64 {
    let base = if cfg!(fuzzing) { 8 } else { 20 };
    base + (bytes as u64 >> 23)
}

/// Runs `f` in a child process; Err where the child did not end normally.
/// `bytes`: the file's size, for the CPU-time limit.
#[cfg(unix)]
pub(super) fn survives(budget: u64, bytes: usize, f: impl FnOnce()) -> Result<(), String> {
    let seconds = cpu_seconds(bytes);
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
            if !cfg!(fuzzing) {
                let limit = libc::rlimit {
                    rlim_cur: address_space().saturating_add(budget),
                    rlim_max: libc::RLIM_INFINITY,
                };
                libc::setrlimit(libc::RLIMIT_AS, &limit);
            }
            let cpu = libc::rlimit {
                rlim_cur: seconds,
                rlim_max: seconds + 1,
            };
            libc::setrlimit(libc::RLIMIT_CPU, &cpu);
            for sig in [
                libc::SIGXCPU,
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
        // A panic is fine: the parent's read meets it again and reports it.
        let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        // SAFETY: ends the child without running the parent's destructors.
        unsafe { libc::_exit(0) };
    }
    let mut status = 0;
    let waited = loop {
        // SAFETY: waits for our own child.
        let w = unsafe { libc::waitpid(pid, &mut status, 0) };
        // A signal to this process (a timer's, as libFuzzer's every
        // second) interrupts the wait: wait again. Returning early would
        // read in this process the file the child may be stuck on.
        if w >= 0 || std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted {
            break w;
        }
    };
    if waited != pid {
        return Ok(());
    }
    if libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0 {
        return Ok(());
    }
    let how = if libc::WIFSIGNALED(status) && libc::WTERMSIG(status) == libc::SIGXCPU {
        format!("stopped after {seconds} s of CPU time (it does not end)")
    } else if libc::WIFSIGNALED(status) {
        format!(
            "stopped by signal {} (the file asks for more memory than the budget, or the reader crashed)",
            libc::WTERMSIG(status)
        )
    } else {
        format!(
            "stopped with status {} (the file asks for more memory than the budget, or the reader crashed)",
            libc::WEXITSTATUS(status)
        )
    };
    Err(format!("the USD reader was {how} on this file"))
}

/// This process's address space in bytes (`/proc/self/statm`'s size; 0
/// where it cannot be read).
#[cfg(unix)]
fn address_space() -> u64 {
    let pages = std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .unwrap_or(0);
    // SAFETY: sysconf with a valid name.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    pages.saturating_mul(u64::try_from(page).unwrap_or(4096))
}

/// Without fork: read in this process.
#[cfg(not(unix))]
pub(super) fn survives(_budget: u64, _bytes: usize, _f: impl FnOnce()) -> Result<(), String> {
    Ok(())
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A read that ends normally passes, a panic too (the parent meets it
    /// again); one whose allocation the machine refuses (here: beyond the
    /// child's address-space limit) aborts the child and is an error, as
    /// is a child that exits with another status.
    #[test]
    fn an_abort_in_the_child_is_an_error_not_the_end_of_the_process() {
        assert!(survives(1 << 30, 0, || {}).is_ok());
        assert!(survives(1 << 30, 0, || panic!("caught")).is_ok());
        let e = survives(1 << 30, 0, || {
            let v = vec![1u8; 1 << 40];
            std::hint::black_box(&v);
        })
        .unwrap_err();
        assert!(e.contains("stopped by signal"), "{e}");
        let e = survives(1 << 30, 0, || std::process::exit(7)).unwrap_err();
        assert!(e.contains("status 7"), "{e}");
        // A signal that interrupts the wait does not end it early.
        // SAFETY: a handler that does nothing, installed without
        // SA_RESTART, so that the signal interrupts waitpid; a thread
        // sends it while the child is still running.
        unsafe {
            extern "C" fn nothing(_: libc::c_int) {}
            let mut sa: libc::sigaction = std::mem::zeroed();
            sa.sa_sigaction = nothing as *const () as usize;
            libc::sigaction(libc::SIGUSR1, &sa, std::ptr::null_mut());
        }
        // SAFETY: pthread_self has no preconditions.
        let parent = unsafe { libc::pthread_self() };
        let poke = std::thread::spawn(move || {
            for _ in 0..5 {
                std::thread::sleep(std::time::Duration::from_millis(20));
                // SAFETY: signals a thread of this process that lives.
                unsafe { libc::pthread_kill(parent, libc::SIGUSR1) };
            }
        });
        let e = survives(1 << 30, 0, || {
            std::thread::sleep(std::time::Duration::from_millis(300));
            std::process::exit(9)
        })
        .unwrap_err();
        poke.join().unwrap();
        assert!(e.contains("status 9"), "{e}");
        // The CPU-time limit grows with the file: 20 s, one more per 8 MiB.
        assert_eq!(cpu_seconds(1000), 20);
        assert_eq!(cpu_seconds(80 << 20), 30);
    }
}
