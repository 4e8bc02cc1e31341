//! A team of threads kept across steps (`docs/engine.md`, "Threads"): the narrow phase and the
//! impulse solve run their work on it. Nothing a team does decides a result: its users split
//! their work so that any thread may take any part of it and the answer is the serial one.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// Spins a waiting thread this many times before it yields its core: a phase of the solve
/// lasts microseconds, longer than the other thread's arrival takes on an idle core, and a
/// yield lets that thread run where the cores are shared.
const SPINS_BEFORE_YIELD: u32 = 2_000;

/// Fewest items in a chunk of [`Team::in_order`]: a bed of a few pellets stays on the calling
/// thread, where waking another would cost more than its share of the work.
const MIN_CHUNK: usize = 16;

/// Chunks per thread of [`Team::in_order`]: items differ in cost (a sphere pair is closed form,
/// a ring pair samples hundreds of points), so the work is handed out in a few chunks a thread.
const CHUNKS_PER_THREAD: usize = 4;

/// `threads` threads: the calling one and, for more than one, a rayon pool of the others,
/// started once and parked between uses.
#[derive(Debug, Clone, Default)]
pub struct Team {
    threads: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl Team {
    /// A team of `threads` threads (0 or 1: the calling thread alone). A pool that cannot be
    /// started leaves the calling thread alone, which gives the same results.
    pub fn new(threads: usize) -> Self {
        let threads = threads.max(1);
        if threads == 1 {
            return Self { threads, pool: None };
        }
        match rayon::ThreadPoolBuilder::new()
            .num_threads(threads - 1)
            .thread_name(|k| format!("pellet-sim-{}", k + 1))
            .build()
        {
            Ok(pool) => Self { threads, pool: Some(Arc::new(pool)) },
            Err(_) => Self { threads: 1, pool: None },
        }
    }

    /// Threads in the team (at least 1).
    pub fn threads(&self) -> usize {
        self.threads.max(1)
    }

    /// Runs `work(k, barrier)` on `min(n, threads)` threads at once, k = 0 on the calling
    /// thread; `barrier` holds each of them until all have reached it.
    pub fn run(&self, n: usize, work: impl Fn(usize, &Barrier) + Sync) {
        let n = n.clamp(1, self.threads());
        let barrier = Barrier::new(n);
        // A thread that panics poisons the barrier, so that the others panic at it instead of
        // waiting for it for ever.
        let guarded = |k: usize, barrier: &Barrier| {
            let _poison = PoisonOnPanic(barrier);
            work(k, barrier);
        };
        match &self.pool {
            Some(pool) if n > 1 => pool.in_place_scope(|scope| {
                let (guarded, barrier) = (&guarded, &barrier);
                for k in 1..n {
                    scope.spawn(move |_| guarded(k, barrier));
                }
                guarded(0, barrier);
            }),
            _ => work(0, &barrier),
        }
    }

    /// What `work` appends for `items`, on the team's threads: the items are split into chunks
    /// in order (at least `MIN_CHUNK` items, up to `CHUNKS_PER_THREAD` a thread; a thread that
    /// is done takes the next), each chunk's output is kept apart, and the outputs are joined
    /// in chunk order, so the result is the serial one whichever thread ran which chunk. An
    /// error is the first in that order (a chunk stops at its first, as the serial loop does).
    pub(crate) fn in_order<T: Send, R: Send, E: Send>(
        &self,
        items: &mut [T],
        work: impl Fn(&mut [T], &mut Vec<R>) -> Result<(), E> + Sync,
    ) -> Result<Vec<R>, E> {
        let chunks = (items.len() / MIN_CHUNK).clamp(1, self.threads() * CHUNKS_PER_THREAD);
        let workers = self.threads().clamp(1, chunks);
        if workers == 1 {
            let mut out = Vec::with_capacity(items.len());
            work(items, &mut out)?;
            return Ok(out);
        }
        let size = items.len().div_ceil(chunks);
        type Slot<'a, T, R, E> = Mutex<(&'a mut [T], Vec<R>, Result<(), E>)>;
        let slots: Vec<Slot<'_, T, R, E>> =
            items.chunks_mut(size).map(|c| Mutex::new((c, Vec::with_capacity(size), Ok(())))).collect();
        let next = AtomicUsize::new(0);
        self.run(workers, |_, _| {
            while let Some(slot) = slots.get(next.fetch_add(1, Ordering::Relaxed)) {
                let mut slot = slot.lock().unwrap_or_else(PoisonError::into_inner);
                let (chunk, out, result) = &mut *slot;
                *result = work(chunk, out);
            }
        });
        let parts: Vec<_> = slots.into_iter().map(|s| s.into_inner().unwrap_or_else(PoisonError::into_inner)).collect();
        let mut joined = Vec::with_capacity(parts.iter().map(|(_, out, _)| out.len()).sum());
        for (_, out, result) in parts {
            result?;
            joined.extend(out);
        }
        Ok(joined)
    }
}

/// A barrier for the threads of one [`Team::run`]: each waits, spinning and then yielding,
/// until all have arrived.
pub struct Barrier {
    n: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    poisoned: AtomicBool,
}

/// Marks its barrier poisoned if dropped while its thread unwinds.
struct PoisonOnPanic<'a>(&'a Barrier);

impl Drop for PoisonOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.poisoned.store(true, Ordering::Release);
        }
    }
}

impl Barrier {
    fn new(n: usize) -> Self {
        Self { n, arrived: AtomicUsize::new(0), generation: AtomicUsize::new(0), poisoned: AtomicBool::new(false) }
    }

    /// Waits until all the run's threads have called it as often as this one.
    pub fn wait(&self) {
        if self.n == 1 {
            return;
        }
        let generation = self.generation.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.n {
            // Reset before the release, so that no thread reaches the next wait early.
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.fetch_add(1, Ordering::Release);
            return;
        }
        let mut spins = 0u32;
        while self.generation.load(Ordering::Acquire) == generation {
            if self.poisoned.load(Ordering::Acquire) {
                panic!("another thread of the team panicked");
            }
            if spins < SPINS_BEFORE_YIELD {
                spins += 1;
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thread that panics makes the run panic, not hang: the others stop at the barrier.
    #[test]
    fn a_panic_on_one_thread_ends_the_run() {
        let team = Team::new(2);
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            team.run(2, |k, barrier| {
                if k == 1 {
                    panic!("thread 1 fails");
                }
                barrier.wait();
            })
        }));
        assert!(result.is_err());
    }

    /// Every thread sees every other's writes of a round after the barrier that ends it.
    #[test]
    fn a_barrier_separates_rounds() {
        for threads in [1, 2, 3] {
            let team = Team::new(threads);
            let slots: Vec<Mutex<u64>> = (0..3).map(|_| Mutex::new(0)).collect();
            let bad = AtomicUsize::new(0);
            team.run(3, |k, barrier| {
                for round in 1..=200u64 {
                    if k < slots.len() {
                        *slots[k].lock().unwrap() = round;
                    }
                    barrier.wait();
                    for (j, s) in slots.iter().enumerate().take(team.threads().min(3)) {
                        if *s.lock().unwrap() != round {
                            bad.fetch_add(1 + j, Ordering::Relaxed);
                        }
                    }
                    barrier.wait();
                }
            });
            assert_eq!(bad.load(Ordering::Relaxed), 0, "{threads} threads");
        }
    }

    #[test]
    fn chunks_are_joined_in_order_for_any_thread_count() {
        let serial: Vec<u64> = (0..1000u64).flat_map(|k| 0..k % 5).collect();
        for threads in [1, 2, 3, 8] {
            let mut items: Vec<u64> = (0..1000).collect();
            let out = Team::new(threads)
                .in_order(&mut items, |chunk, out| {
                    for k in chunk.iter_mut() {
                        out.extend(0..*k % 5);
                        *k += 1;
                    }
                    Ok::<(), ()>(())
                })
                .unwrap();
            assert_eq!(out, serial, "{threads} threads");
            assert!(items.iter().enumerate().all(|(k, &v)| v == k as u64 + 1), "each item once");
        }
    }

    #[test]
    fn the_first_error_in_order_is_returned() {
        let mut items: Vec<u32> = (0..500).collect();
        let err = Team::new(3)
            .in_order(&mut items, |chunk, out: &mut Vec<u32>| {
                for &mut k in chunk {
                    if k == 123 || k == 400 {
                        return Err(k);
                    }
                    out.push(k);
                }
                Ok(())
            })
            .unwrap_err();
        assert_eq!(err, 123);
    }
}
