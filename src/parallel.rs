//! How many threads a computation may use, per calling thread: [`with_threads`] caps it,
//! [`join`] runs two independent parts side by side when the cap allows two threads and one
//! after the other otherwise. Every parallel split of the library (the representative beside
//! the solver's analysis, nested dissection's two halves, the two-way factorisation, weight
//! functions) goes through it, and none changes what is computed: the orderings and plans are
//! chosen from the problem alone, so results are bit-identical for every thread count.
//!
//! ```
//! use toposmooth::parallel::{default_threads, join, threads, with_threads};
//! assert_eq!(threads(), default_threads());
//! let (a, b) = with_threads(1, || join(threads, threads));
//! assert_eq!((a, b), (1, 1));
//! ```

use std::cell::Cell;

/// The cap when no caller set one: every core of the machine
/// (`std::thread::available_parallelism`, which honours the process's CPU affinity and
/// cgroup quota), 2 where it is unknown.
pub fn default_threads() -> usize {
    static DEFAULT: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *DEFAULT.get_or_init(|| std::thread::available_parallelism().map_or(2, std::num::NonZeroUsize::get))
}

thread_local! {
    /// 0: no cap set on this thread (the default applies).
    static LIMIT: Cell<usize> = const { Cell::new(0) };
}

/// The number of threads the current thread's computations may use (at least 1).
pub fn threads() -> usize {
    match LIMIT.with(Cell::get) {
        0 => default_threads(),
        n => n,
    }
}

/// Runs `f` with at most `n` threads (`n` = 0 is taken as 1), restoring the previous cap after.
pub fn with_threads<R>(n: usize, f: impl FnOnce() -> R) -> R {
    struct Restore(usize);
    impl Drop for Restore {
        fn drop(&mut self) {
            LIMIT.with(|l| l.set(self.0));
        }
    }
    let _restore = Restore(LIMIT.with(|l| l.replace(n.max(1))));
    f()
}

/// Factor flops from which a numeric factorisation uses faer's parallel kernels (on 2 cores
/// rayon only paid off for the largest factors measured).
pub const PARALLEL_FACTOR_FLOPS: f64 = 2e10;

static PARALLEL_FLOPS: std::sync::atomic::AtomicU64 =
    std::sync::atomic::AtomicU64::new(PARALLEL_FACTOR_FLOPS.to_bits());

/// The factor flops from which factorisations use faer's parallel kernels now.
pub fn parallel_factor_flops() -> f64 {
    f64::from_bits(PARALLEL_FLOPS.load(std::sync::atomic::Ordering::Relaxed))
}

/// Factorisations of at least `flops` use faer's parallel kernels (0: every one; the default is
/// [`PARALLEL_FACTOR_FLOPS`]): for tests that check that the parallel kernels give the same
/// bits for every thread count.
#[doc(hidden)]
pub fn set_parallel_factor_flops(flops: f64) {
    PARALLEL_FLOPS.store(flops.to_bits(), std::sync::atomic::Ordering::Relaxed);
}

/// faer's parallelism for a dense or supernodal kernel under the cap: sequential for one
/// thread, else at most the cap's threads of faer's global setting.
pub fn faer_par() -> faer::Par {
    match (threads(), faer::get_global_parallelism()) {
        (n, faer::Par::Rayon(global)) if n >= 2 => faer::Par::rayon(n.min(global.get())),
        _ => faer::Par::Seq,
    }
}

/// Runs `a` on this thread and `b` on another when two threads are allowed (the cap is split
/// between them), else `a` then `b` here. A panic in either is propagated; the run's
/// cancellation token ([`crate::progress::cancellable`]) is checked on both.
pub fn join<RA, RB: Send>(a: impl FnOnce() -> RA, b: impl FnOnce() -> RB + Send) -> (RA, RB) {
    let n = threads();
    if n < 2 {
        let ra = a();
        return (ra, b());
    }
    let (na, nb) = (n - n / 2, n / 2);
    let token = crate::progress::token();
    std::thread::scope(|scope| {
        let other = scope.spawn(move || crate::progress::with_token(token, || with_threads(nb, b)));
        let ra = with_threads(na, a);
        (ra, other.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    })
}

/// Elements from which [`split_mut`] and [`split_mut2`] put a loop on several threads (below,
/// a thread's start costs more than the loop).
pub const SPLIT_FROM: usize = 1 << 17;

/// The contiguous pieces of `n` elements for the current cap: at least [`SPLIT_FROM`] / 2 each.
fn pieces(n: usize) -> usize {
    threads().min(n / (SPLIT_FROM / 2)).max(1)
}

/// Runs `f(offset, piece)` on contiguous pieces of `a`, on up to the cap's threads: for loops
/// whose every element is computed alone (no sum across elements), which give the same bits on
/// any number of threads.
pub fn split_mut<A: Send>(a: &mut [A], f: impl Fn(usize, &mut [A]) + Sync) {
    let t = pieces(a.len());
    if t < 2 {
        f(0, a);
        return;
    }
    let chunk = a.len().div_ceil(t);
    let f = &f;
    std::thread::scope(|scope| {
        let mut pieces = a.chunks_mut(chunk).enumerate();
        let (_, first) = pieces.next().expect("at least one piece");
        for (i, piece) in pieces {
            scope.spawn(move || with_threads(1, || f(i * chunk, piece)));
        }
        with_threads(1, || f(0, first));
    });
}

/// Runs `f` on every item of `items`, on up to the cap's threads, each thread a contiguous run
/// of at least `min_items` items: for work cut into blocks fixed by the data (a sum per block,
/// the blocks' sums added in order after), which gives the same bits on any number of threads.
pub fn for_each_mut<A: Send>(items: &mut [A], min_items: usize, f: impl Fn(&mut A) + Sync) {
    let t = threads().min(items.len() / min_items.max(1)).max(1);
    if t < 2 {
        items.iter_mut().for_each(f);
        return;
    }
    let chunk = items.len().div_ceil(t);
    let f = &f;
    std::thread::scope(|scope| {
        let mut pieces = items.chunks_mut(chunk);
        let first = pieces.next().expect("at least one piece");
        for piece in pieces {
            scope.spawn(move || with_threads(1, || piece.iter_mut().for_each(f)));
        }
        with_threads(1, || first.iter_mut().for_each(f));
    });
}

/// [`split_mut`] over two slices of the same length, split at the same places.
///
/// # Panics
/// If the lengths differ.
pub fn split_mut2<A: Send, B: Send>(a: &mut [A], b: &mut [B], f: impl Fn(usize, &mut [A], &mut [B]) + Sync) {
    assert_eq!(a.len(), b.len(), "split_mut2 over slices of different lengths");
    let t = pieces(a.len());
    if t < 2 {
        f(0, a, b);
        return;
    }
    let chunk = a.len().div_ceil(t);
    let f = &f;
    std::thread::scope(|scope| {
        let mut pieces = a.chunks_mut(chunk).zip(b.chunks_mut(chunk)).enumerate();
        let (_, (a0, b0)) = pieces.next().expect("at least one piece");
        for (i, (pa, pb)) in pieces {
            scope.spawn(move || with_threads(1, || f(i * chunk, pa, pb)));
        }
        with_threads(1, || f(0, a0, b0));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cap_is_split_and_restored() {
        assert_eq!(threads(), default_threads());
        let main = std::thread::current().id();
        let (a, b) = with_threads(4, || join(|| (threads(), std::thread::current().id()), threads));
        assert_eq!((a.0, b), (2, 2));
        assert_eq!(a.1, main, "a runs on the calling thread");
        let ids = with_threads(1, || join(|| std::thread::current().id(), || std::thread::current().id()));
        assert_eq!(ids, (main, main), "one thread: both parts here");
        assert_eq!(threads(), default_threads());
        let r = std::panic::catch_unwind(|| with_threads(3, || -> usize { panic!("inside") }));
        assert!(r.is_err());
        assert_eq!(threads(), default_threads(), "restored after a panic");
        // faer's kernels follow the cap: one thread is sequential
        assert_eq!(with_threads(1, faer_par), faer::Par::Seq);
    }

    #[test]
    fn split_loops_cover_every_element_once_at_its_offset() {
        for n in [0, 5, SPLIT_FROM - 1, SPLIT_FROM, 3 * SPLIT_FROM + 11] {
            for t in [1, 2, 3, 8] {
                let mut a = vec![0usize; n];
                let mut b = vec![0u8; n];
                with_threads(t, || {
                    split_mut(&mut a, |off, piece| {
                        for (i, v) in piece.iter_mut().enumerate() {
                            *v += off + i + 1;
                        }
                    });
                    split_mut2(&mut a, &mut b, |off, pa, pb| {
                        for (i, (v, w)) in pa.iter_mut().zip(pb.iter_mut()).enumerate() {
                            assert_eq!(*v, off + i + 1);
                            *w += 1;
                        }
                    });
                });
                assert!(a.iter().enumerate().all(|(i, &v)| v == i + 1), "n = {n}, {t} threads");
                assert!(b.iter().all(|&w| w == 1));
                let mut items: Vec<(usize, usize)> = (0..n % 1000).map(|i| (i, 0)).collect();
                with_threads(t, || for_each_mut(&mut items, 3, |(i, v)| *v = *i + 1));
                assert!(items.iter().all(|&(i, v)| v == i + 1), "{} items, {t} threads", n % 1000);
            }
        }
    }
}
