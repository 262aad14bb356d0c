//! [`Banks`]: what a [`Scene`](super::Scene) steps, a [`Bank`] or a tuple or array of them.

use super::{Bank, Layout, Sleep};
use crate::Integrator;
use lagrange_core::{Mechanism, Real};

/// The banks of a scene, stepped together: one [`Bank`], a mutable reference to banks, or a
/// tuple (up to 8) or an array of values that are [`Banks`] themselves, stepped in order (a tuple's first element
/// first, an array's from index 0).
pub trait Banks<T: Real> {
    /// Steps every awake instance of every bank once by `dt`, landing at time `t`, in the
    /// documented order; returns how many instances failed this step.
    fn step(&mut self, dt: T, t: T) -> u32;

    /// Sets the time of every bank, and of every instance in it, to `t`.
    fn set_time(&mut self, t: T);
}

impl<T, const N: usize, const K: usize, M, I, Z, Y> Banks<T> for Bank<T, N, K, M, I, Z, Y>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
    Y: Layout<T, N, K, M>,
{
    #[inline]
    fn step(&mut self, dt: T, t: T) -> u32 {
        Bank::step(self, dt, t)
    }

    fn set_time(&mut self, t: T) {
        Bank::set_time(self, t);
    }
}

/// Banks owned elsewhere (a `static`, a game's own storage), stepped by a scene that borrows
/// them.
impl<T: Real, B: Banks<T> + ?Sized> Banks<T> for &mut B {
    #[inline]
    fn step(&mut self, dt: T, t: T) -> u32 {
        (**self).step(dt, t)
    }

    fn set_time(&mut self, t: T) {
        (**self).set_time(t);
    }
}

impl<T: Real, B: Banks<T>, const L: usize> Banks<T> for [B; L] {
    fn step(&mut self, dt: T, t: T) -> u32 {
        self.iter_mut().map(|b| b.step(dt, t)).sum()
    }

    fn set_time(&mut self, t: T) {
        for b in self {
            b.set_time(t);
        }
    }
}

/// `Banks` for a tuple of banks, stepped from the first element to the last.
macro_rules! tuple_banks {
    ($($name:ident $index:tt),+) => {
        impl<T: Real, $($name: Banks<T>),+> Banks<T> for ($($name,)+) {
            fn step(&mut self, dt: T, t: T) -> u32 {
                0 $(+ self.$index.step(dt, t))+
            }

            fn set_time(&mut self, t: T) {
                $(self.$index.set_time(t);)+
            }
        }
    };
}

tuple_banks!(A 0);
tuple_banks!(A 0, B 1);
tuple_banks!(A 0, B 1, C 2);
tuple_banks!(A 0, B 1, C 2, D 3);
tuple_banks!(A 0, B 1, C 2, D 3, E 4);
tuple_banks!(A 0, B 1, C 2, D 3, E 4, F 5);
tuple_banks!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
tuple_banks!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);
