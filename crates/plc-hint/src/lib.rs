//! Cache hints: ask the CPU to start bringing a cache line closer before it is used, so that
//! the misses of several lines overlap instead of each stalling the code that needs it. A hint
//! changes no value the program computes, only when memory arrives; it never faults, whatever
//! the address. Below every stage of the pipeline (the resolver's name tables and the parallel
//! scan use it); it knows nothing of either.
//!
//! - [`prefetch_read`]: `PREFETCHT0`, the line in every cache level, for reading.
//! - [`prefetch_write`]: `PREFETCHW`, the line in the exclusive state, for writing: a line that
//!   another core holds is taken from it now (its copy invalidated), not when the first store to
//!   it reaches the head of the store buffer. Where the CPU has no `PREFETCHW` (checked once, by
//!   CPUID), it falls back to `PREFETCHT0`; on other architectures both are no-ops.
//!
//! What it does not do: decide what to prefetch (its callers know their access patterns).
//! Under Miri, which runs neither CPUID nor inline assembly, both are no-ops, as they are on
//! other architectures (a hint changes no value, so the program Miri checks is the same).

/// Asks the CPU to start loading the cache line holding `at` for reading (a hint).
#[inline(always)]
pub fn prefetch_read(at: *const u8) {
    #[cfg(all(target_arch = "x86_64", not(miri)))]
    // SAFETY: `_mm_prefetch` needs SSE, which every x86_64 CPU has (it is in the target's
    // baseline); a prefetch never faults and reads nothing into the program: any address is
    // allowed.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(at.cast())
    };
    #[cfg(any(not(target_arch = "x86_64"), miri))]
    let _ = at;
}

/// Asks the CPU to start taking the cache line holding `at` for writing (a hint): exclusive in
/// this core's cache, invalidated in the others.
#[inline(always)]
pub fn prefetch_write(at: *const u8) {
    #[cfg(all(target_arch = "x86_64", not(miri)))]
    if has_prefetchw() {
        // SAFETY: the CPU implements PREFETCHW (CPUID 8000_0001h ECX bit 8, checked by
        // `has_prefetchw`); like every prefetch it never faults, whatever the address, and
        // changes no register, flag or memory the program sees.
        unsafe {
            std::arch::asm!("prefetchw [{0}]", in(reg) at, options(nostack, readonly, preserves_flags))
        };
    } else {
        prefetch_read(at);
    }
    #[cfg(any(not(target_arch = "x86_64"), miri))]
    let _ = at;
}

/// Whether the CPU has PREFETCHW (read once, then cached).
#[cfg(all(target_arch = "x86_64", not(miri)))]
#[inline(always)]
fn has_prefetchw() -> bool {
    use std::sync::atomic::{AtomicU8, Ordering};
    /// 0: not read yet; 1: no; 2: yes.
    static HAS: AtomicU8 = AtomicU8::new(0);
    match HAS.load(Ordering::Relaxed) {
        0 => {
            let yes = cpuid_prefetchw();
            HAS.store(1 + yes as u8, Ordering::Relaxed);
            yes
        }
        v => v == 2,
    }
}

#[cfg(all(target_arch = "x86_64", not(miri)))]
#[cold]
fn cpuid_prefetchw() -> bool {
    use std::arch::x86_64::__cpuid;
    // Leaf 8000_0000h gives the highest extended leaf; 8000_0001h is asked only if it exists.
    __cpuid(0x8000_0000).eax >= 0x8000_0001 && __cpuid(0x8000_0001).ecx & (1 << 8) != 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hints_change_nothing_and_accept_any_address() {
        let v = vec![7u8; 256];
        for i in 0..v.len() {
            prefetch_read(v.as_ptr().wrapping_add(i));
            prefetch_write(v.as_ptr().wrapping_add(i));
        }
        // Past the end and null: a hint never faults.
        prefetch_read(v.as_ptr().wrapping_add(1 << 40));
        prefetch_write(std::ptr::null());
        assert!(v.iter().all(|&b| b == 7));
    }
}
