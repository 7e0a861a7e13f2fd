//! The step's threads held together for the whole step, and the pieces of work a stage
//! hands them.
//!
//! A step has dozens of short parallel stages: four substeps of a warm start, several
//! solve and relax passes per graph colour, kicks and drifts. Fork–join on rayon paid a
//! worker's wake-up (tens of µs, futex and scheduler) for nearly every one of them, since
//! rayon's idle workers fall asleep within microseconds: the first parallel passes made two
//! threads *slower* than one (see `contact_wide.rs`, `GROUPS_A_PIECE`'s history). Box2D v3
//! keeps its workers spinning through its solver's stages instead; so does this. A
//! [`Team`] is started once per step (`Workers::run`): the other threads of the world's
//! pool join it and spin, waiting for work, until the step ends; a stage posts a job of
//! n pieces, every member (the posting thread too) claims pieces until none is left, and
//! the posting thread returns once all n are done. A hand-off is then an atomic store and
//! a few cache-line transfers, about a microsecond.
//!
//! Results never depend on which thread runs which piece: a stage's pieces write disjoint
//! data (the stage says why), so pieces claimed in any order give the same bits. Nor does
//! the step depend on the members arriving at all: the posting thread claims pieces too,
//! so if the pool's other threads are busy elsewhere (worlds stepped side by side on one
//! pool), it does every piece itself and nothing waits on a thread that never comes.
//!
//! Members spin between jobs, and sleep on a condition variable after 200 µs without one
//! (`AWAKE`): through a solver's passes they stay awake, in a step with little to split
//! they leave the core alone. The team is only formed for worlds large enough to split
//! (`SMALL_WORLD` in `pipeline/world/step.rs`).

use std::any::Any;
use std::cell::{Cell, RefCell};
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

/// The most pieces one job may have (a job of more runs on rayon's threads instead).
pub(crate) const MAX_PIECES: usize = 256;

/// A piece's claim: the number of the last job that claimed it, on a cache line of its
/// own (neighbouring pieces are claimed by different threads at the same moment).
#[repr(align(64))]
#[derive(Default)]
struct Claim(AtomicU64);

/// Spins of a waiting thread before it yields its core between checks (the posting
/// thread waiting for pieces) or sleeps until the next job (a member).
const SPINS: u32 = 1 << 12;

/// How long a member spins without a job before it sleeps: long enough to stay awake
/// through a solver's passes (jobs some µs apart), short enough that a step with little
/// to split (a few hundred bodies) does not have a core spinning for nothing: members
/// that only yielded their core slowed such a step by 20 % on this 2-core machine.
const AWAKE: std::time::Duration = std::time::Duration::from_micros(200);

/// A job as the members see it: the work for each piece, how many pieces, its number.
#[derive(Clone, Copy)]
struct Job {
    work: *const (dyn Fn(usize) + Sync + 'static),
    count: usize,
    number: u64,
}

// SAFETY: `work` points at a `Sync` closure, so calling it from any thread is sound while
// it lives; `Team::run` keeps it alive until every piece that can call it has returned
// (see there).
unsafe impl Send for Job {}

/// What the members of a team share.
struct Shared {
    /// The job being handed out, behind a lock that members take once per job.
    job: Mutex<Option<Job>>,
    /// The latest job's number, which members poll.
    posted: AtomicU64,
    /// Per piece, the last job that claimed it. Job numbers only grow, so a piece is
    /// free for job n while its claim is below n, and no claim is ever reset.
    claims: Box<[Claim]>,
    /// Pieces of the latest job that have returned.
    done: AtomicUsize,
    /// Set when the team's region ends: members leave.
    over: AtomicBool,
    /// Members asleep, or about to be, and what wakes them (see `sleep`).
    sleeping: AtomicUsize,
    bell: (Mutex<()>, Condvar),
    /// The first panic of a piece, raised again on the posting thread.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
}

/// A step's threads, held from [`region`]'s start to its end.
pub(crate) struct Team {
    shared: Arc<Shared>,
    number: Cell<u64>,
    threads: usize,
    /// A job of this team is being run: a piece that asks for pieces of its own runs them
    /// itself (a second job would strand the first one's unclaimed pieces).
    busy: Cell<bool>,
}

thread_local! {
    /// The team whose region the current thread runs, if any (the posting thread's).
    static CURRENT: RefCell<Option<Rc<Team>>> = const { RefCell::new(None) };
}

/// Runs `f` with a team of `threads` threads of the current rayon pool (the calling
/// thread and `threads − 1` members that join as they are free), so that [`pieces`]
/// inside `f` hand work to them.
pub(crate) fn region<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    if threads <= 1 || CURRENT.with(|c| c.borrow().is_some()) {
        return f();
    }
    let shared = Arc::new(Shared {
        job: Mutex::new(None),
        posted: AtomicU64::new(0),
        claims: (0..MAX_PIECES).map(|_| Claim::default()).collect(),
        done: AtomicUsize::new(0),
        over: AtomicBool::new(false),
        sleeping: AtomicUsize::new(0),
        bell: (Mutex::new(()), Condvar::new()),
        panic: Mutex::new(None),
    });
    let result = rayon::scope(|s| {
        for member in 1..threads {
            let shared = Arc::clone(&shared);
            s.spawn(move |_| serve(&shared, (member, threads)));
        }
        let team = Team {
            shared: Arc::clone(&shared),
            number: Cell::new(0),
            threads,
            busy: Cell::new(false),
        };
        CURRENT.with(|c| *c.borrow_mut() = Some(Rc::new(team)));
        let result = catch_unwind(AssertUnwindSafe(f));
        CURRENT.with(|c| *c.borrow_mut() = None);
        shared.over.store(true, Ordering::SeqCst);
        ring(&shared);
        result
    });
    result.unwrap_or_else(|p| resume_unwind(p))
}

/// Calls `work(i)` for every i in `0..count`, each exactly once, on the current team's
/// threads if this thread runs a team's region, else on rayon's (when `threads` > 1) or
/// in order. `work` must give the same result whichever thread runs which piece and in
/// whatever order (pieces writing disjoint data).
pub(crate) fn pieces(threads: usize, count: usize, work: &(dyn Fn(usize) + Sync)) {
    if count <= 1 || threads <= 1 {
        return (0..count).for_each(work);
    }
    let team = CURRENT.with(|c| c.borrow().clone());
    match team {
        Some(team) if count <= MAX_PIECES => team.run(count, work),
        _ => {
            use rayon::prelude::*;
            (0..count).into_par_iter().for_each(work);
        }
    }
}

impl Team {
    /// Posts `work` as a job of `count` pieces, takes part, and returns when all are done.
    fn run(&self, count: usize, work: &(dyn Fn(usize) + Sync)) {
        if self.busy.replace(true) {
            return (0..count).for_each(work);
        }
        let panic = self.post(count, work);
        self.busy.set(false);
        if let Some(p) = panic {
            resume_unwind(p);
        }
    }

    /// [`Team::run`]'s job; returns the first panic of its pieces.
    fn post(&self, count: usize, work: &(dyn Fn(usize) + Sync)) -> Option<Box<dyn Any + Send>> {
        let shared = &*self.shared;
        let number = self.number.get() + 1;
        self.number.set(number);
        // SAFETY (the lifetime made 'static): the pointer is called only by a thread that
        // has claimed a piece of this job: a compare-exchange that raised the piece's
        // claim from below this job's number to it. Until every piece is done, this
        // function does not return (the wait below counts `done`, which a piece adds to
        // only after `work` returned, also when it panicked), so `work` is alive at every
        // call; after that, every piece's claim is this job's number, so no claim for
        // this job (or an older one) can succeed again.
        let work: &'static (dyn Fn(usize) + Sync) = unsafe { std::mem::transmute(work) };
        {
            let mut job = shared.job.lock().unwrap_or_else(|p| p.into_inner());
            *job = Some(Job {
                work,
                count,
                number,
            });
            shared.done.store(0, Ordering::Relaxed);
        }
        shared.posted.store(number, Ordering::SeqCst);
        ring(shared);
        let job = Job {
            work,
            count,
            number,
        };
        work_on(shared, job, (0, self.threads));
        let mut spins = 0u32;
        while shared.done.load(Ordering::Acquire) < count {
            wait(&mut spins);
        }
        let panic = shared
            .panic
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take();
        panic
    }
}

/// Member `member` of `threads`' loop: wait for a job, take part in it, until the region
/// ends.
fn serve(shared: &Shared, member: (usize, usize)) {
    let mut seen = 0u64;
    let mut idle_since = Instant::now();
    let mut spins = 0u32;
    while !shared.over.load(Ordering::Acquire) {
        let posted = shared.posted.load(Ordering::Acquire);
        if posted == seen {
            spins += 1;
            std::hint::spin_loop();
            if spins.is_multiple_of(256) && idle_since.elapsed() > AWAKE {
                sleep(shared, seen);
                idle_since = Instant::now();
            }
            continue;
        }
        seen = posted;
        let job = *shared.job.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(job) = job {
            work_on(shared, job, member);
        }
        idle_since = Instant::now();
    }
}

/// Sleeps until a job after `seen` is posted or the region ends. The count of sleepers
/// goes up before the last look at `posted`, and the poster reads it after its store
/// (both sequentially consistent), so either this member sees the new job or the poster
/// sees a sleeper and rings, under the lock this member waits on: no wake-up is lost.
fn sleep(shared: &Shared, seen: u64) {
    shared.sleeping.fetch_add(1, Ordering::SeqCst);
    let (lock, bell) = &shared.bell;
    let mut guard = lock.lock().unwrap_or_else(|p| p.into_inner());
    while shared.posted.load(Ordering::SeqCst) == seen && !shared.over.load(Ordering::SeqCst) {
        guard = bell.wait(guard).unwrap_or_else(|p| p.into_inner());
    }
    drop(guard);
    shared.sleeping.fetch_sub(1, Ordering::SeqCst);
}

/// Wakes the sleeping members, if any (a new job, or the region's end).
fn ring(shared: &Shared) {
    if shared.sleeping.load(Ordering::SeqCst) > 0 {
        let _guard = shared.bell.0.lock().unwrap_or_else(|p| p.into_inner());
        shared.bell.1.notify_all();
    }
}

/// Claims and runs pieces of `job` until none is left: member m of n first its own
/// share (pieces m·count/n.. (m+1)·count/n, so that a thread meets the same bodies in
/// consecutive jobs and keeps them in its cache), then the others' that are still free.
fn work_on(shared: &Shared, job: Job, (member, threads): (usize, usize)) {
    let start = member * job.count / threads.max(1);
    for i in (start..job.count).chain(0..start) {
        if !claim(shared, &job, i) {
            continue;
        }
        // SAFETY: piece i of `job` was claimed, so `job.work` is alive (see `Team::run`).
        let work = unsafe { &*job.work };
        if let Err(p) = catch_unwind(AssertUnwindSafe(|| work(i))) {
            let mut slot = shared.panic.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert(p);
        }
        shared.done.fetch_add(1, Ordering::AcqRel);
    }
}

/// Claims piece `i` for `job`: true if it was free (its claim below the job's number).
fn claim(shared: &Shared, job: &Job, i: usize) -> bool {
    let slot = &shared.claims[i].0;
    let mut was = slot.load(Ordering::Acquire);
    while was < job.number {
        match slot.compare_exchange_weak(was, job.number, Ordering::AcqRel, Ordering::Acquire) {
            Ok(_) => return true,
            Err(now) => was = now,
        }
    }
    false
}

/// One round of waiting: a spin, or past [`SPINS`] of them a yield of the core.
fn wait(spins: &mut u32) {
    if *spins < SPINS {
        *spins += 1;
        std::hint::spin_loop();
    } else {
        std::thread::yield_now();
    }
}

/// A slice handed out in disjoint parts to the pieces of one job.
pub(crate) struct Parts<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: a `Parts` is a `&mut [T]` split between threads, each part reached by one piece
// only (see `part`): sharing it is sending those parts, sound when `T: Send`.
unsafe impl<T: Send> Sync for Parts<'_, T> {}

impl<'a, T> Parts<'a, T> {
    pub fn new(slice: &'a mut [T]) -> Parts<'a, T> {
        Parts {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _borrow: std::marker::PhantomData,
        }
    }

    /// Elements `range` as a slice of their own.
    ///
    /// # Safety
    /// While the result lives, no other call may return a slice overlapping `range`: the
    /// pieces of a job must each ask for their own range, disjoint from every other's.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn part(&self, range: std::ops::Range<usize>) -> &mut [T] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds (checked), borrowed exclusively for 'a by `new`, and by this
        // function's contract no other live slice covers these elements.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.len()) }
    }
}

/// Calls `work(start, part)` on consecutive parts of `data` of `size` elements (the last
/// may be shorter), as [`pieces`] of one job; each part is its piece's alone.
pub(crate) fn chunks<T: Send>(
    threads: usize,
    data: &mut [T],
    size: usize,
    work: &(dyn Fn(usize, &mut [T]) + Sync),
) {
    let size = size.max(1);
    let count = data.len().div_ceil(size);
    let len = data.len();
    let parts = Parts::new(data);
    pieces(threads, count, &|i| {
        let range = i * size..((i + 1) * size).min(len);
        // SAFETY: piece i takes elements i·size.. (i+1)·size alone, and each piece runs
        // once, so the parts never overlap.
        let part = unsafe { parts.part(range.clone()) };
        work(range.start, part);
    });
}

/// What [`chunks2`] calls: the first element's index, and the parts of both slices.
pub(crate) type PairWork<'a, A, B> = dyn Fn(usize, &mut [A], &mut [B]) + Sync + 'a;

/// [`chunks`] over two slices of one length at once: piece i gets elements
/// i·size.. (i+1)·size of both.
pub(crate) fn chunks2<A: Send, B: Send>(
    threads: usize,
    (a, b): (&mut [A], &mut [B]),
    size: usize,
    work: &PairWork<'_, A, B>,
) {
    assert_eq!(a.len(), b.len());
    let size = size.max(1);
    let (count, len) = (a.len().div_ceil(size), a.len());
    let (a, b) = (Parts::new(a), Parts::new(b));
    pieces(threads, count, &|i| {
        let range = i * size..((i + 1) * size).min(len);
        // SAFETY: as in `chunks`: piece i's elements are its own.
        let (pa, pb) = unsafe { (a.part(range.clone()), b.part(range.clone())) };
        work(range.start, pa, pb);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pool(n: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    }

    #[test]
    fn every_piece_runs_once_in_a_region_and_out_of_one() {
        for threads in [1, 2, 3, 8] {
            pool(threads).install(|| {
                let check = || {
                    for count in [0, 1, 2, 7, 1000] {
                        let hits: Vec<AtomicUsize> =
                            (0..count).map(|_| AtomicUsize::new(0)).collect();
                        pieces(threads, count, &|i| {
                            hits[i].fetch_add(1, Ordering::Relaxed);
                        });
                        assert!(hits.iter().all(|h| h.load(Ordering::Relaxed) == 1));
                    }
                };
                check();
                region(threads, check);
            });
        }
    }

    #[test]
    fn chunks_cover_the_slice_once() {
        pool(3).install(|| {
            region(3, || {
                let mut data = vec![0u32; 1003];
                for _ in 0..50 {
                    chunks(3, &mut data, 10, &|start, part| {
                        for (k, x) in part.iter_mut().enumerate() {
                            *x += (start + k) as u32;
                        }
                    });
                }
                assert!(data.iter().enumerate().all(|(k, &x)| x == 50 * k as u32));
            });
        });
    }

    #[test]
    fn a_panicking_piece_reaches_the_caller_and_the_team_goes_on() {
        pool(2).install(|| {
            region(2, || {
                let caught = catch_unwind(|| pieces(2, 4, &|i| assert!(i != 2, "piece two")));
                assert!(caught.is_err());
                let sum = AtomicUsize::new(0);
                pieces(2, 100, &|i| {
                    sum.fetch_add(i, Ordering::Relaxed);
                });
                assert_eq!(sum.load(Ordering::Relaxed), 4950);
            });
        });
    }

    #[test]
    fn a_team_whose_members_are_busy_still_finishes() {
        // A pool of two whose other thread is held by a region of its own: neither team
        // gets a member, both do their pieces alone.
        pool(2).install(|| {
            rayon::join(
                || region(2, || pieces(2, 64, &|_| std::hint::black_box(()))),
                || region(2, || pieces(2, 64, &|_| std::hint::black_box(()))),
            );
        });
    }
}
