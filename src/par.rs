//! Parallel iteration over slices with rayon when the `parallel` feature is
//! on, one item after another otherwise. The sweeps call `par_iter().map(..)
//! .collect()` and `join`, the Rapier impact pass [`for_each_mut`] on a
//! batch's independent impacts; each item's result does not depend on the
//! order or the thread, so both give the same values.

#[cfg(feature = "parallel")]
#[allow(unused_imports)] // `join` is the stress soak's, which needs both Rapier builds
pub(crate) use rayon::{join, prelude};

/// Sequential stand-ins for the rayon items the crate uses.
#[cfg(not(feature = "parallel"))]
pub(crate) mod prelude {
    /// `par_iter` on a slice: here the slice's plain iterator.
    pub(crate) trait IntoParallelRefIterator<T> {
        /// The items in order.
        fn par_iter(&self) -> std::slice::Iter<'_, T>;
    }

    impl<T> IntoParallelRefIterator<T> for [T] {
        fn par_iter(&self) -> std::slice::Iter<'_, T> {
            self.iter()
        }
    }
}

/// Runs `a` then `b` (rayon's `join` runs them on two threads).
#[cfg(not(feature = "parallel"))]
#[cfg_attr(not(all(feature = "f32", feature = "f64")), allow(dead_code))] // the stress soak's
pub(crate) fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA,
    B: FnOnce() -> RB,
{
    let ra = a();
    (ra, b())
}

/// Calls `f` on every item of `items`: on rayon's pool with the `parallel`
/// feature (each item on one thread, the items shared out among the
/// pool's threads), in order without it. `f` must not depend on the order.
#[cfg_attr(not(any(feature = "f32", feature = "f64")), allow(dead_code))] // the Rapier pass's
pub(crate) fn for_each_mut<T: Send>(items: &mut [T], f: impl Fn(&mut T) + Sync + Send) {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        items.par_iter_mut().for_each(f);
    }
    #[cfg(not(feature = "parallel"))]
    items.iter_mut().for_each(f);
}

#[cfg(test)]
mod tests {
    use super::prelude::*;

    #[test]
    fn par_iter_keeps_the_order_and_join_runs_both() {
        let v = [1, 2, 3, 4];
        let squares: Vec<i32> = v.par_iter().map(|x| x * x).collect();
        assert_eq!(squares, [1, 4, 9, 16]);
        assert_eq!(super::join(|| 1, || "b"), (1, "b"));
        let mut w = [1, 2, 3];
        super::for_each_mut(&mut w, |x| *x *= 10);
        assert_eq!(w, [10, 20, 30]);
    }
}
