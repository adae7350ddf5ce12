mod cli;

fn main() {
    if let Some(missing) = missing_cpu_feature() {
        refuse(missing);
    }
    if let Err(e) = softraster::render::forced_lane_width() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
    keep_freed_memory();
    std::process::exit(cli::main());
}

/// Each frame allocates and frees the same large buffers (set-up
/// triangles, vertices, per-corner tangents: over 200 MB at 1.3 million
/// triangles). glibc serves blocks above its mmap threshold (128 KiB,
/// rising to at most 32 MiB) with fresh pages and unmaps them when they are
/// freed, so every frame faulted them in again, zeroed by the kernel: a
/// quarter of such a frame. The CLI takes blocks below 1 GiB from the heap
/// and keeps freed memory up to 1 GiB for the next frame. A
/// `GLIBC_TUNABLES` that sets malloc parameters is left to rule.
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        if std::env::var("GLIBC_TUNABLES").is_ok_and(|t| t.contains("glibc.malloc.")) {
            return;
        }
        const GIB: libc::c_int = 1 << 30;
        // SAFETY: mallopt only sets allocator parameters; it is called
        // before any thread exists.
        unsafe {
            if libc::mallopt(libc::M_MMAP_THRESHOLD, GIB) == 0 {
                // A glibc that caps the threshold: no mmap at all.
                libc::mallopt(libc::M_MMAP_MAX, 0);
            }
            libc::mallopt(libc::M_TRIM_THRESHOLD, GIB);
        }
    }
}

/// The first instruction-set extension of x86-64-v3 that this build was
/// compiled for (`.cargo/config.toml`) and the CPU lacks. Asked of CPUID
/// itself: `is_x86_feature_detected!` answers true without asking for a
/// feature the build was compiled with.
fn missing_cpu_feature() -> Option<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::__cpuid_count;
        // Leaves above the highest one the CPU reports are not read.
        let (max, max_ext) = (__cpuid_count(0, 0).eax, __cpuid_count(0x8000_0000, 0).eax);
        let l1 = __cpuid_count(1, 0);
        let l7b = if max >= 7 { __cpuid_count(7, 0).ebx } else { 0 };
        let ext = if max_ext >= 0x8000_0001 {
            __cpuid_count(0x8000_0001, 0).ecx
        } else {
            0
        };
        // The OS saves the AVX registers (OSXSAVE, then XCR0's SSE and AVX
        // state bits).
        let os_avx = l1.ecx & (1 << 27) != 0 && {
            // SAFETY: XGETBV exists where CPUID reports OSXSAVE.
            let xcr0 = unsafe { xgetbv0() };
            xcr0 & 0b110 == 0b110
        };
        let bit = |r: u32, b: u32| r & (1 << b) != 0;
        // (AVX state: the OS must save the registers too.)
        let vex = |b: u32| bit(l1.ecx, b) && os_avx;
        // Name, whether this build uses it, whether the CPU has it.
        let checks = [
            ("sse3", cfg!(target_feature = "sse3"), bit(l1.ecx, 0)),
            ("ssse3", cfg!(target_feature = "ssse3"), bit(l1.ecx, 9)),
            ("fma", cfg!(target_feature = "fma"), vex(12)),
            ("sse4.1", cfg!(target_feature = "sse4.1"), bit(l1.ecx, 19)),
            ("sse4.2", cfg!(target_feature = "sse4.2"), bit(l1.ecx, 20)),
            ("movbe", cfg!(target_feature = "movbe"), bit(l1.ecx, 22)),
            ("popcnt", cfg!(target_feature = "popcnt"), bit(l1.ecx, 23)),
            ("avx", cfg!(target_feature = "avx"), vex(28)),
            ("f16c", cfg!(target_feature = "f16c"), vex(29)),
            ("bmi1", cfg!(target_feature = "bmi1"), bit(l7b, 3)),
            ("avx2", cfg!(target_feature = "avx2"), bit(l7b, 5) && os_avx),
            ("bmi2", cfg!(target_feature = "bmi2"), bit(l7b, 8)),
            ("lzcnt", cfg!(target_feature = "lzcnt"), bit(ext, 5)),
        ];
        for (name, built_for, present) in checks {
            if built_for && !present {
                return Some(name);
            }
        }
    }
    None
}

/// XCR0, the state components the OS saves (XGETBV with ECX = 0).
///
/// # Safety
/// The CPU must have XGETBV (CPUID.1:ECX.OSXSAVE).
#[cfg(target_arch = "x86_64")]
unsafe fn xgetbv0() -> u64 {
    let (lo, hi): (u32, u32);
    // SAFETY: the caller checked OSXSAVE; XGETBV only reads a register.
    unsafe {
        std::arch::asm!("xgetbv", in("ecx") 0u32, out("eax") lo, out("edx") hi,
            options(nomem, nostack, preserves_flags));
    }
    (u64::from(hi) << 32) | u64::from(lo)
}

/// Exits with a message on a CPU the build cannot run on, before any of
/// the renderer's code (which may use the missing instructions) runs.
#[cold]
#[inline(never)]
fn refuse(missing: &str) -> ! {
    use std::io::Write;
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(b"softraster: this build needs the CPU feature ");
    let _ = err.write_all(missing.as_bytes());
    let _ = err.write_all(
        b" (it targets x86-64-v3, see .cargo/config.toml); on this machine build with\n  \
          RUSTFLAGS=\"-C target-cpu=x86-64\" cargo build --release\n\
          (the same frames, byte for byte, about 10% slower)\n",
    );
    std::process::exit(3);
}
