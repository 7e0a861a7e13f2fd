//! Threads: how many a world steps on, the worker pools behind them, and the rule a stage
//! follows to split its work.
//!
//! Every parallel stage is written so that its result does not depend on how its work is
//! split: each piece writes only what no other piece reads or writes (the narrow phase's
//! pairs each fill their own list, joined in pair order; the graph colours' manifolds
//! share no moving body), so one thread or sixty-four give the same bits. A stage splits
//! only past a size below which the hand-off to other threads costs more than it saves
//! (`Par::pieces`), so a small world runs serially whatever the thread count.
//!
//! Worlds with the same thread count share one pool (rayon's), kept while any of them
//! lives: tests and batches make thousands of worlds, and a pool of threads each is 50 µs
//! to start and megabytes of stacks.

use crate::error::{Error, Result};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, Weak};

/// The most threads a world may ask for.
pub const MAX_THREADS: usize = 256;

/// The environment variable that sets the default thread count.
pub const THREADS_ENV: &str = "TUMBLE_THREADS";

/// The thread count a world gets unless it asks: `TUMBLE_THREADS` if set to a count in
/// 1..=[`MAX_THREADS`], else every core the operating system offers this process.
pub fn default_threads() -> usize {
    match std::env::var(THREADS_ENV) {
        Ok(text) => match parse_threads(&text) {
            Ok(n) => n,
            Err(_) => available(),
        },
        Err(_) => available(),
    }
}

/// `TUMBLE_THREADS` read and checked: `Ok(None)` when unset, an error naming the variable
/// when it is not a count in 1..=[`MAX_THREADS`].
pub fn threads_from_env() -> Result<Option<usize>> {
    match std::env::var(THREADS_ENV) {
        Ok(text) => parse_threads(&text)
            .map(Some)
            .map_err(|e| Error::invalid(THREADS_ENV, e)),
        Err(_) => Ok(None),
    }
}

fn parse_threads(text: &str) -> std::result::Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("must be a whole number of threads, got {text:?}"))?;
    check_count(n)
}

/// Checks a thread count: 1..=[`MAX_THREADS`].
pub(crate) fn check(threads: usize) -> Result<usize> {
    check_count(threads).map_err(|e| Error::invalid("threads", e))
}

fn check_count(n: usize) -> std::result::Result<usize, String> {
    if (1..=MAX_THREADS).contains(&n) {
        Ok(n)
    } else {
        Err(format!("must be between 1 and {MAX_THREADS}, got {n}"))
    }
}

fn available() -> usize {
    std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(MAX_THREADS)
}

/// A world's threads: the count, and the shared pool once a step needs it.
#[derive(Default)]
pub(crate) struct Workers {
    threads: usize,
    pool: Option<Arc<rayon::ThreadPool>>,
}

/// The pools of every thread count in use, shared by the worlds that use it.
static POOLS: Mutex<Vec<(usize, Weak<rayon::ThreadPool>)>> = Mutex::new(Vec::new());

impl Workers {
    pub fn new(threads: usize) -> Workers {
        Workers {
            threads: threads.clamp(1, MAX_THREADS),
            pool: None,
        }
    }

    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Runs `f` on this world's pool, its threads held as a team for `f`'s length (see
    /// `team.rs`), with the step's splitting rule; on the calling thread if the world has
    /// one thread, or if no pool can be started (then serially: the results are the
    /// same).
    pub fn run<R: Send>(&mut self, f: impl FnOnce(Par) -> R + Send) -> R {
        if self.threads == 1 {
            return f(Par::SERIAL);
        }
        if self.pool.is_none() {
            self.pool = shared_pool(self.threads);
        }
        match &self.pool {
            Some(pool) => {
                let par = Par {
                    threads: self.threads,
                };
                pool.install(|| crate::team::region(par.threads, || f(par)))
            }
            None => f(Par::SERIAL),
        }
    }
}

/// The pool of `threads` threads that other worlds use, or a new one.
pub(crate) fn shared_pool(threads: usize) -> Option<Arc<rayon::ThreadPool>> {
    let mut pools = POOLS.lock().unwrap_or_else(|p| p.into_inner());
    pools.retain(|(_, weak)| weak.strong_count() > 0);
    if let Some(pool) = pools
        .iter()
        .find(|(n, _)| *n == threads)
        .and_then(|(_, weak)| weak.upgrade())
    {
        return Some(pool);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("tumble-{i}"))
        .build()
        .ok()?;
    let pool = Arc::new(pool);
    pools.push((threads, Arc::downgrade(&pool)));
    Some(pool)
}

/// How a step may split its work: the thread count it runs on (1: serially).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Par {
    pub threads: usize,
}

impl Default for Par {
    fn default() -> Par {
        Par::SERIAL
    }
}

/// Whether stages split work of any size (see [`split_everything`]).
static EAGER: AtomicBool = AtomicBool::new(false);

/// Makes every stage split its work however small (`true`), as if the thresholds were
/// one unit: for tests that a split gives the same bits on scenes small enough to run
/// quickly. Results never depend on it, only speed.
#[doc(hidden)]
pub fn split_everything(on: bool) {
    EAGER.store(on, Ordering::Relaxed);
}

impl Par {
    pub const SERIAL: Par = Par { threads: 1 };

    /// How many pieces of `least` units `items` makes: the thresholds' test, the same on
    /// every thread count.
    pub fn split_at(items: usize, least: usize) -> usize {
        let least = if EAGER.load(Ordering::Relaxed) {
            1
        } else {
            least.max(1)
        };
        items / least
    }

    /// Into how many pieces to split `items` units of work of which a piece should have
    /// at least `least` (below that a piece's hand-off costs more than it saves): 1 when
    /// serial or small, else a multiple of the thread count up to four pieces a thread,
    /// so that uneven pieces even out. Not a multiple, equal pieces leave a thread idle
    /// at the end: a graph colour of 100 lane groups in three pieces gave one of two
    /// threads two of them (the rain's contact passes, 5 % faster on two threads split
    /// in twos).
    pub fn pieces(&self, items: usize, least: usize) -> usize {
        if self.threads <= 1 {
            return 1;
        }
        let n = Par::split_at(items, least);
        if n < self.threads {
            return n.max(1);
        }
        (n / self.threads * self.threads).min(4 * self.threads)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_outside_one_to_the_most_are_refused() {
        assert!(check(0).is_err());
        assert!(check(MAX_THREADS + 1).is_err());
        assert_eq!(check(3).unwrap(), 3);
        assert!(parse_threads("two").is_err());
        assert!(parse_threads("-1").is_err());
        assert_eq!(parse_threads(" 4 ").unwrap(), 4);
    }

    #[test]
    fn small_work_is_not_split() {
        let par = Par { threads: 4 };
        assert_eq!(par.pieces(10, 64), 1);
        assert_eq!(par.pieces(640, 64), 8);
        assert_eq!(par.pieces(192, 64), 3);
        assert_eq!(par.pieces(64_000, 64), 16);
        assert_eq!(Par::SERIAL.pieces(64_000, 64), 1);
    }

    #[test]
    fn worlds_of_one_count_share_a_pool() {
        let (mut a, mut b) = (Workers::new(3), Workers::new(3));
        let ta = a.run(|_| rayon::current_num_threads());
        b.run(|_| ());
        assert_eq!(ta, 3);
        assert!(Arc::ptr_eq(
            a.pool.as_ref().unwrap(),
            b.pool.as_ref().unwrap()
        ));
        assert_eq!(Workers::new(1).run(|p| p), Par::SERIAL);
    }
}
