//! Pinning the workers of a run to CPUs: worker `i` to the `i`-th CPU the process may run on,
//! for the duration of the run, when there are at least as many such CPUs as workers (Linux
//! `sched_getaffinity` / `sched_setaffinity`). A pinned worker is never migrated, and two
//! workers never share a CPU while a third is idle; each thread's previous mask comes back when
//! its part of the run ends ([`Pinned`]'s drop), so neither the calling thread nor the pool's
//! threads stay pinned after the run.
//!
//! Pinning changes where a thread runs, never what it computes. It does nothing (and says so
//! with `None`) on other systems, with fewer CPUs than workers, or when a call fails (a
//! container that forbids it): the run goes on unpinned. Depends on nothing in the parallel
//! module.

/// The CPUs the calling thread may run on, ascending (empty if unknown).
pub(super) fn allowed_cpus() -> Vec<usize> {
    imp::allowed_cpus()
}

/// A thread pinned to one CPU until dropped (then its previous mask is restored).
pub(super) struct Pinned(#[allow(dead_code)] imp::Saved);

/// Pins the calling thread to `cpu`; `None` if that failed or is not supported.
pub(super) fn pin_to(cpu: usize) -> Option<Pinned> {
    imp::pin_to(cpu).map(Pinned)
}

#[cfg(target_os = "linux")]
mod imp {
    use std::mem::{size_of, zeroed};

    /// The mask a thread had before it was pinned.
    pub(super) struct Saved(libc::cpu_set_t);

    fn current() -> Option<libc::cpu_set_t> {
        // SAFETY: `cpu_set_t` is plain bits (all zero is the empty set); the call writes at
        // most `size_of::<cpu_set_t>()` bytes into it and reads nothing else.
        unsafe {
            let mut set: libc::cpu_set_t = zeroed();
            (libc::sched_getaffinity(0, size_of::<libc::cpu_set_t>(), &mut set) == 0).then_some(set)
        }
    }

    fn set(set: &libc::cpu_set_t) -> bool {
        // SAFETY: `set` is a valid, initialised `cpu_set_t` of the size given; pid 0 is the
        // calling thread.
        unsafe { libc::sched_setaffinity(0, size_of::<libc::cpu_set_t>(), set) == 0 }
    }

    pub(super) fn allowed_cpus() -> Vec<usize> {
        let Some(set) = current() else {
            return Vec::new();
        };
        (0..libc::CPU_SETSIZE as usize)
            // SAFETY: `i` is below CPU_SETSIZE, the bit count of `set`.
            .filter(|&i| unsafe { libc::CPU_ISSET(i, &set) })
            .collect()
    }

    pub(super) fn pin_to(cpu: usize) -> Option<Saved> {
        if cpu >= libc::CPU_SETSIZE as usize {
            return None;
        }
        let old = current()?;
        // SAFETY: as in `current`; `cpu` is below CPU_SETSIZE.
        let mut one: libc::cpu_set_t = unsafe { zeroed() };
        // SAFETY: `cpu` is below CPU_SETSIZE, the bit count of `one`.
        unsafe { libc::CPU_SET(cpu, &mut one) };
        set(&one).then_some(Saved(old))
    }

    impl Drop for Saved {
        fn drop(&mut self) {
            set(&self.0);
        }
    }
}

#[cfg(not(target_os = "linux"))]
mod imp {
    pub(super) struct Saved;

    pub(super) fn allowed_cpus() -> Vec<usize> {
        Vec::new()
    }

    pub(super) fn pin_to(_cpu: usize) -> Option<Saved> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pinning moves the thread to the CPU and dropping the guard gives its mask back.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_pinned_thread_runs_on_its_cpu_and_gets_its_mask_back() {
        std::thread::spawn(|| {
            let before = allowed_cpus();
            assert!(!before.is_empty());
            let last = *before.last().expect("a cpu");
            {
                let _p = pin_to(last).expect("pinning to an allowed cpu");
                assert_eq!(allowed_cpus(), vec![last]);
                // SAFETY: sched_getcpu has no preconditions.
                assert_eq!(unsafe { libc::sched_getcpu() }, last as i32);
            }
            assert_eq!(allowed_cpus(), before);
        })
        .join()
        .expect("the test thread");
    }
}
