//! How the process asks the kernel for memory: in ordinary 4 KiB pages, not transparent huge
//! pages.
//!
//! The allocator (mimalloc) marks its arenas `MADV_HUGEPAGE`. On Linux hosts whose
//! `transparent_hugepage/defrag` is `madvise` (Debian's and Ubuntu's default), a fault in such
//! a region may compact memory synchronously to find a free 2 MiB page, and then zeroes all
//! of it. On a shared 2-core host, a million-rung `plc-deps report` (1.3 GB of fresh memory)
//! spent 2.0–4.4 s of its 3.5–6.2 s in the kernel with huge pages and 0.7–0.8 s without them
//! (`/usr/bin/time`, 4 interleaved runs each, `MIMALLOC_ALLOW_THP=0` against the default,
//! 3 December 2026, load average 6–8): kernel page zeroing (`clear_page_erms`) was the one part
//! of the run that grew faster than the program — 46× from 100,000 to 1,000,000 rungs, against
//! 9–12× for everything the analysis itself does (`perf record`). Without huge pages user time
//! grows by about a tenth (more TLB misses), far less than the kernel time saved.
//!
//! So [`prefer_small_pages`] turns transparent huge pages off for this process
//! (`prctl(PR_SET_THP_DISABLE)`, which the kernel checks on every fault, also in regions already
//! marked `MADV_HUGEPAGE`; it is what mimalloc's own `MIMALLOC_ALLOW_THP=0` does). It changes no
//! result, only where the kernel's time goes. Elsewhere than Linux it does nothing.
//!
//! Not here: how much memory the commands use (the analyses and the report model decide that).

/// Asks the kernel not to back this process's memory with transparent huge pages (see the
/// module's comment). Call it once, first thing in `main`; failure is ignored (an older kernel
/// simply keeps its default).
pub fn prefer_small_pages() {
    #[cfg(target_os = "linux")]
    // SAFETY: `prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0)` takes plain integers, reads and writes no
    // memory of this process, and only sets a flag of the calling process (inherited by its
    // children); its return value is not needed.
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, 1, 0, 0, 0);
    }
}
