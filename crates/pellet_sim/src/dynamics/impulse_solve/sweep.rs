//! The Gauss–Seidel sweeps of the impulse solve over the slabs' tasks (`slabs`), on one thread
//! or several: each half sweep's tasks share no body, so whichever thread runs a task, and in
//! whatever order, the answer is the serial one bit for bit.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::slabs::Layout;
use super::{onto_disk, Block, ImpulseSolution, NormalTarget, PatchBlock, Velocities, VelocityState, WarmStart};
use crate::geometry::contact::Contact;
use crate::math::{Real, Vec3};
use crate::team::Team;

/// Fewest contacts a solve hands to more than one thread: below, a half sweep's work is
/// shorter than the wait for the other thread.
pub(super) const MIN_PARALLEL_CONTACTS: usize = 128;

/// A solve whose blocks still change after this many sweeps also asks, every `STILL_EVERY`
/// sweeps, whether those sweeps changed the bodies' velocities (`Solve::net_change`): most
/// solves end within a few sweeps without the question.
const STILL_AFTER: usize = 4;
const STILL_EVERY: usize = 8;
/// Velocities that moved by less than this fraction of the tolerance over `STILL_EVERY`
/// sweeps have stopped: a solve still converging moves them by more than the tolerance over
/// as many sweeps, as its changes add up where a drift's cancel.
const STILL_FRACTION: Real = 0.1;

/// A slab's bodies: their velocities and, per body, how often a block has changed them.
#[derive(Debug, Default)]
struct Bodies {
    v: Vec<Vec3>,
    w: Vec<Vec3>,
    version: Vec<u64>,
}

/// The two slabs a task works on: indices below `split` are the lower slab's.
struct View<'a> {
    lo: &'a mut Bodies,
    hi: &'a mut Bodies,
    split: usize,
}

impl View<'_> {
    /// The slab that holds body `i` of the view, and its index there.
    #[inline]
    fn slot(&mut self, i: usize) -> (&mut Bodies, usize) {
        if i < self.split {
            (&mut *self.lo, i)
        } else {
            (&mut *self.hi, i - self.split)
        }
    }

    #[inline]
    fn version(&mut self, i: usize) -> &mut u64 {
        let (b, k) = self.slot(i);
        &mut b.version[k]
    }
}

impl Velocities for View<'_> {
    #[inline]
    fn v(&mut self, i: usize) -> &mut Vec3 {
        let (b, k) = self.slot(i);
        &mut b.v[k]
    }
    #[inline]
    fn w(&mut self, i: usize) -> &mut Vec3 {
        let (b, k) = self.slot(i);
        &mut b.w[k]
    }
}

/// One slab's contacts: their blocks (bodies as indices of the task's `View`), impulses, and
/// the skip test's records.
#[derive(Debug, Default)]
struct Task {
    /// The contacts' indices in the solve.
    ids: Vec<usize>,
    blocks: Vec<Block>,
    patches: Vec<Option<PatchBlock>>,
    ln: Vec<Real>,
    lt: Vec<[Real; 2]>,
    lw: Vec<[Real; 3]>,
    /// The block's last visit changed nothing that counts...
    quiet: Vec<bool>,
    /// ...and its bodies' versions after it: a quiet block whose bodies nobody has changed
    /// since would change nothing again, and is passed by. In a bed at rest most blocks are.
    seen: Vec<[u64; 2]>,
}

/// The solve's state, by slab and task.
pub(super) struct Solve<'a> {
    layout: &'a Layout,
    slabs: Vec<Mutex<Bodies>>,
    tasks: Vec<Mutex<Task>>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// What a solve starts from: the contacts, their targets and warm starts, and the bodies'
/// free velocities and masses.
pub(super) struct Problem<'a> {
    pub contacts: &'a [Contact],
    pub targets: &'a [NormalTarget],
    pub warm: &'a [WarmStart],
    pub st: &'a VelocityState,
}

impl<'a> Solve<'a> {
    /// The velocities of `st` by slab of `layout`, and an empty task per slab.
    pub fn new(layout: &'a Layout, st: &VelocityState) -> Self {
        let slabs = layout
            .slabs
            .iter()
            .map(|ids| {
                Mutex::new(Bodies {
                    v: ids.iter().map(|&i| st.v[i]).collect(),
                    w: ids.iter().map(|&i| st.w[i]).collect(),
                    version: vec![0; ids.len()],
                })
            })
            .collect();
        Self { layout, slabs, tasks: layout.tasks.iter().map(|_| Mutex::new(Task::default())).collect() }
    }

    /// Task `s`'s blocks (bodies by index of the task's `View`) and their starting impulses,
    /// the warm start clamped to the blocks' bounds. Reads the bodies' masses only.
    fn build(&self, s: usize, problem: &Problem<'_>) {
        let ids = &self.layout.tasks[s];
        let split = self.layout.slabs[s].len();
        let local = |i: usize| {
            let (slab, k) = self.layout.place[i];
            k as usize + if slab as usize == s { 0 } else { split }
        };
        let n = ids.len();
        let mut task = Task {
            ids: ids.clone(),
            blocks: Vec::with_capacity(n),
            patches: Vec::with_capacity(n),
            ln: Vec::with_capacity(n),
            lt: Vec::with_capacity(n),
            lw: Vec::with_capacity(n),
            ..Task::default()
        };
        for &k in ids {
            let (c, w, target) = (&problem.contacts[k], &problem.warm[k], &problem.targets[k]);
            let mut blk = Block::new(c, problem.st, target);
            let patch = PatchBlock::new(c, &blk, problem.st, target);
            blk.a = local(c.a);
            if let Some(j) = c.b_body() {
                blk.b = local(j);
            }
            let n0 = w.normal.max(0.0);
            let mut l = [0.0; 3];
            if let Some(p) = &patch {
                l = blk.dir.map(|d| d.dot(&w.torque));
                p.clamp(&mut l, n0);
            }
            task.lt.push(onto_disk([w.friction.dot(&blk.dir[1]), w.friction.dot(&blk.dir[2])], blk.mu * n0));
            task.blocks.push(blk);
            task.patches.push(patch);
            task.ln.push(n0);
            task.lw.push(l);
        }
        task.quiet = vec![false; n];
        task.seen = vec![[0; 2]; n];
        *lock(&self.tasks[s]) = task;
    }

    /// `f` on task `s` and the view of its two slabs.
    fn with_view<R>(&self, s: usize, f: impl FnOnce(&mut Task, &mut View<'_>) -> R) -> R {
        let mut task = lock(&self.tasks[s]);
        let mut lo = lock(&self.slabs[s]);
        let mut empty = Bodies::default();
        let mut hi_guard = self.slabs.get(s + 1).map(lock);
        let split = lo.v.len();
        let hi = hi_guard.as_deref_mut().unwrap_or(&mut empty);
        f(&mut task, &mut View { lo: &mut lo, hi, split })
    }

    /// Builds the blocks (on the threads), applies their starting impulses (on one), and sweeps
    /// until a sweep changes no relative velocity by more than `tolerance` (m/s), or
    /// `max_sweeps`; a block's change below `negligible` is not applied. Returns the sweeps, the
    /// last residual and whether it converged.
    ///
    /// The solve also ends when `STILL_EVERY` sweeps leave every body's velocity where they
    /// found it, to within `STILL_FRACTION` of `tolerance` at the farthest contact point,
    /// while its blocks still change: the impulses then only move along a direction that no
    /// velocity feels (friction forces of a pellet on several points that cancel each other,
    /// shifting from point to point at their Coulomb bounds), every sweep alike, and more
    /// sweeps give the same step. The residual reported is then the blocks' change, as for any
    /// solve.
    pub fn run(
        &self,
        problem: &Problem<'_>,
        negligible: Real,
        tolerance: Real,
        max_sweeps: usize,
        team: &Team,
    ) -> ImpulseSolution {
        let sizes: Vec<usize> = self.layout.tasks.iter().map(Vec::len).collect();
        let halves: [Vec<usize>; 2] = [0, 1].map(|h| (h..sizes.len()).step_by(2).filter(|&s| sizes[s] > 0).collect());
        let contacts: usize = sizes.iter().sum();
        if contacts == 0 {
            return ImpulseSolution { converged: true, ..ImpulseSolution::default() };
        }
        let threads = if contacts < MIN_PARALLEL_CONTACTS { 1 } else { halves[0].len().max(halves[1].len()) };
        // Each task's change in the sweep, kept for two sweeps: a thread may start the next
        // sweep while another still reads this one's.
        let change: [Vec<AtomicU64>; 2] = [0, 1].map(|_| sizes.iter().map(|_| AtomicU64::new(0)).collect());
        // The next task of a half sweep, one counter for each of three half sweeps in a row:
        // the one two ahead is reset once everybody is done with it.
        let next: [AtomicU64; 3] = [0, 1, 0].map(|h| AtomicU64::new(ends_of(halves[h].len())));
        let built = AtomicUsize::new(0);
        let outcome = Mutex::new((0, 0.0, false));
        // The velocities the still test compares with, and the farthest contact point from a
        // centre (for the bodies' surface speeds): found by the first test, which few solves
        // reach.
        let last = Mutex::new(None);
        let net = AtomicU64::new(0);
        team.run(threads, |thread, barrier| {
            // The blocks, every task at once: they write no velocity.
            loop {
                let s = built.fetch_add(1, Ordering::Relaxed);
                match sizes.get(s) {
                    Some(&size) if size > 0 => self.build(s, problem),
                    Some(_) => {}
                    None => break,
                }
            }
            barrier.wait();
            let mut phase = 0usize;
            let mut half_sweep = |half: &[usize], task: &dyn Fn(usize)| {
                let ends = &next[phase % 3];
                while let Some(k) = take(ends, thread % 2 == 1) {
                    task(half[k]);
                }
                barrier.wait();
                if thread == 0 {
                    next[(phase + 2) % 3].store(ends_of(halves[phase % 2].len()), Ordering::Relaxed);
                }
                phase += 1;
            };
            // The warm starts in task order, on one thread: cheap, and in the halves' order some
            // beds came to rest with fewer solves converged (docs/engine.md, Threads).
            if thread == 0 {
                for s in 0..sizes.len() {
                    self.with_view(s, |task, view| task.warm_start(view));
                }
            }
            barrier.wait();
            for sweep in 1..=max_sweeps {
                let buffer = &change[sweep % 2];
                for half in &halves {
                    half_sweep(half, &|s| {
                        let dv = self.with_view(s, |task, view| task.sweep(view, negligible));
                        buffer[s].store(dv.to_bits(), Ordering::Relaxed);
                    });
                }
                let residual = halves
                    .iter()
                    .flatten()
                    .map(|&s| Real::from_bits(buffer[s].load(Ordering::Relaxed)))
                    .fold(0.0, Real::max);
                let mut converged = residual <= tolerance;
                if !converged && sweep >= STILL_AFTER && (sweep - STILL_AFTER).is_multiple_of(STILL_EVERY) {
                    if thread == 0 {
                        let net_change = self.net_change(&mut lock(&last), problem.contacts);
                        net.store(net_change.to_bits(), Ordering::Relaxed);
                    }
                    barrier.wait();
                    converged = Real::from_bits(net.load(Ordering::Relaxed)) <= STILL_FRACTION * tolerance;
                }
                if converged || sweep == max_sweeps {
                    if thread == 0 {
                        *lock(&outcome) = (sweep, residual, converged);
                    }
                    break;
                }
            }
        });
        let (sweeps, residual, converged) = outcome.into_inner().unwrap_or_else(PoisonError::into_inner);
        ImpulseSolution { sweeps, residual, converged, ..ImpulseSolution::default() }
    }

    /// The largest change of a body's velocity, |Δv| + r·|Δω| (m/s) with r the farthest of
    /// `contacts`' points from its body's centre, since the velocities in `last`, which then
    /// become these; infinite when `last` holds none yet.
    fn net_change(&self, last: &mut Option<(Real, Vec<(Vec3, Vec3)>)>, contacts: &[Contact]) -> Real {
        let fresh = last.is_none();
        let (reach, last) = last.get_or_insert_with(|| {
            let reach = contacts
                .iter()
                .map(|c| c.lever_a.norm().max(if c.b_body().is_some() { c.lever_b.norm() } else { 0.0 }))
                .fold(0.0, Real::max);
            (reach, Vec::new())
        });
        let reach = *reach;
        let mut change: Real = 0.0;
        let mut k = 0;
        for slab in &self.slabs {
            let slab = lock(slab);
            for (v, w) in slab.v.iter().zip(&slab.w) {
                if fresh {
                    last.push((*v, *w));
                } else {
                    let (v0, w0) = &mut last[k];
                    change = change.max((v - *v0).norm() + reach * (w - *w0).norm());
                    (*v0, *w0) = (*v, *w);
                }
                k += 1;
            }
        }
        if fresh {
            Real::INFINITY
        } else {
            change
        }
    }

    /// The velocities back into `st`, and the impulses of the solve's `n` contacts into `sol`.
    pub fn finish(self, n: usize, st: &mut VelocityState, sol: &mut ImpulseSolution) {
        for (slab, ids) in self.slabs.into_iter().zip(&self.layout.slabs) {
            let slab = slab.into_inner().unwrap_or_else(PoisonError::into_inner);
            for ((&i, v), w) in ids.iter().zip(slab.v).zip(slab.w) {
                st.v[i] = v;
                st.w[i] = w;
            }
        }
        sol.normal = vec![0.0; n];
        sol.friction = vec![Vec3::zeros(); n];
        sol.torque = vec![Vec3::zeros(); n];
        for task in self.tasks {
            let task = task.into_inner().unwrap_or_else(PoisonError::into_inner);
            for (k, &id) in task.ids.iter().enumerate() {
                let (b, t, l) = (&task.blocks[k], task.lt[k], task.lw[k]);
                sol.normal[id] = task.ln[k];
                sol.friction[id] = b.dir[1] * t[0] + b.dir[2] * t[1];
                sol.torque[id] = b.dir[0] * l[0] + b.dir[1] * l[1] + b.dir[2] * l[2];
            }
        }
    }
}

/// The untaken tasks of a half sweep, [front, back), packed in one word.
fn ends_of(len: usize) -> u64 {
    len as u64
}

/// Takes the next task of a half sweep from its front or, `from_back`, its back: two threads
/// work from the two ends towards each other, each mostly on the slabs it had the sweep
/// before, whose blocks are still in its core's cache.
fn take(ends: &AtomicU64, from_back: bool) -> Option<usize> {
    let mut cur = ends.load(Ordering::Relaxed);
    loop {
        let (front, back) = (cur >> 32, cur & 0xffff_ffff);
        if front >= back {
            return None;
        }
        let (new, k) =
            if from_back { ((front << 32) | (back - 1), back - 1) } else { (((front + 1) << 32) | back, front) };
        match ends.compare_exchange_weak(cur, new, Ordering::Relaxed, Ordering::Relaxed) {
            Ok(_) => return Some(k as usize),
            Err(now) => cur = now,
        }
    }
}

impl Task {
    /// Applies the blocks' starting impulses to the bodies.
    fn warm_start(&mut self, view: &mut View<'_>) {
        for (k, blk) in self.blocks.iter().enumerate() {
            if let Some(p) = &self.patches[k] {
                for (i, &li) in self.lw[k].iter().enumerate() {
                    p.apply(blk, view, i, li);
                }
            }
            blk.apply(view, 0, self.ln[k]);
            blk.apply(view, 1, self.lt[k][0]);
            blk.apply(view, 2, self.lt[k][1]);
        }
    }

    /// One Gauss–Seidel visit of each block in order; the largest change of a relative
    /// velocity, m/s.
    fn sweep(&mut self, view: &mut View<'_>, negligible: Real) -> Real {
        let Task { blocks, patches, ln, lt, lw, quiet, seen, .. } = self;
        let mut change: Real = 0.0;
        for (k, blk) in blocks.iter().enumerate() {
            let version_b = |view: &mut View<'_>| if blk.b == usize::MAX { 0 } else { *view.version(blk.b) };
            if quiet[k] && *view.version(blk.a) == seen[k][0] && version_b(view) == seen[k][1] {
                continue;
            }
            // The normal row, then the tangential pair with the normal change folded into their
            // relative velocities (K_tn), both written to the bodies in one update.
            let mut dv: Real = 0.0;
            let [un, mut u1, mut u2] = blk.speeds(view);
            let mut delta = [0.0; 3];
            let new = (ln[k] + (blk.target - un) * blk.inv_knn).max(0.0);
            let dl = new - ln[k];
            if dl.abs() * blk.knn > negligible {
                ln[k] = new;
                dv = dl.abs() * blk.knn;
                delta[0] = dl;
                u1 += blk.kt_n[0] * dl;
                u2 += blk.kt_n[1] * dl;
            }
            let bound = blk.mu * ln[k];
            let old = lt[k];
            let t = onto_disk(
                [
                    old[0] - (blk.kt_inv[0][0] * u1 + blk.kt_inv[0][1] * u2),
                    old[1] - (blk.kt_inv[1][0] * u1 + blk.kt_inv[1][1] * u2),
                ],
                bound,
            );
            let d = [t[0] - old[0], t[1] - old[1]];
            let dt = (d[0] * d[0] + d[1] * d[1]).sqrt() * blk.kt_trace;
            if dt > negligible {
                lt[k] = t;
                dv = dv.max(dt);
                delta[1] = d[0];
                delta[2] = d[1];
            }
            if dv > 0.0 {
                blk.apply_all(view, delta);
            }
            if let Some(p) = &patches[k] {
                dv = dv.max(p.visit(blk, view, &mut lw[k], ln[k], negligible));
            }
            quiet[k] = dv == 0.0;
            if !quiet[k] {
                *view.version(blk.a) += 1;
                if blk.b != usize::MAX {
                    *view.version(blk.b) += 1;
                }
            }
            seen[k] = [*view.version(blk.a), version_b(view)];
            change = change.max(dv);
        }
        change
    }
}
