//! A Lagrangian's kinetic energy recorded on a tape and swept: what
//! [`EulerLagrange`](crate::EulerLagrange) uses from [`FROM`](super::FROM) coordinates on.
//!
//! It tries two tapes: one of 384 nodes and 1,024 numbers of gradients, which holds a chain
//! of 20 links (10 nodes a link in `T` and 2 an input; its gradients about 500 numbers; a test
//! below checks), then one of 1,024 nodes and 8,192 numbers; it gives up (`None`, the caller
//! falls back to the jet) where `T` needs more. A `T` that needs the larger tape is recorded twice per call. Each
//! size is its own function kept out of line, so that the stack of the larger tape is taken
//! only while it is used.

use super::sweep::{self, Inputs};
use super::{Node, Tape, Taped, NONE};
use crate::{Lagrangian, Real, Scalar};
use core::any::TypeId;
use nalgebra::{ArrayStorage, SMatrix, SVector};

/// `M = d2T/dq'2` and `T`'s part of `f`, `dT/dq - (d2T/dq'dq) q' - d2T/dq'dt`, from `T` at
/// `(t, q, q')` (time an input where [`Lagrangian::EXPLICIT_TIME`]); with `POTENTIAL`, `f`
/// less `dV/dq` too, from `V` recorded on the same tape after `T` (its angles are `T`'s nodes,
/// see [`TrigNodes`](super::trig::TrigNodes), and one reverse pass of `T - V` gives both
/// gradients); `M` is added to `m` (zero on entry); `None` where they do not fit the largest
/// tape.
pub(crate) fn kinetic<T, S, L, const N: usize, const POTENTIAL: bool>(
    l: &L,
    t: S,
    (q, qd): (&SVector<S, N>, &SVector<S, N>),
    m: &mut SMatrix<S, N, N>,
) -> Option<SVector<S, N>>
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    kinetic_on::<T, S, L, N, POTENTIAL, 384, 1024>(l, t, (q, qd), m).or_else(|| {
        // The smaller tape may have left part of M before its pool ran out.
        m.fill(S::zero());
        kinetic_on::<T, S, L, N, POTENTIAL, 1024, 8192>(l, t, (q, qd), m)
    })
}

/// [`kinetic`] on a tape of `CAP` nodes with `POOL` numbers for the sweep's gradients.
#[inline(never)]
fn kinetic_on<T, S, L, const N: usize, const POTENTIAL: bool, const CAP: usize, const POOL: usize>(
    l: &L,
    t: S,
    (q, qd): (&SVector<S, N>, &SVector<S, N>),
    m: &mut SMatrix<S, N, N>,
) -> Option<SVector<S, N>>
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    let mut storage = heapless::Vec::<Node<S>, CAP>::new();
    // Angles remembered for plain numbers only (see `TrigNodes`); the test folds away.
    let tape = Tape::new(&mut storage, TypeId::of::<S>() == TypeId::of::<T>());
    let (out, inputs) = {
        // Inputs first, in this order: time (where it enters T), q, q'.
        let time = if L::EXPLICIT_TIME {
            tape.input(t)
        } else {
            Taped::constant(t)
        };
        let tq: [Taped<'_, '_, S, CAP>; N] = core::array::from_fn(|k| tape.input(q[k]));
        let tqd: [Taped<'_, '_, S, CAP>; N] = core::array::from_fn(|k| tape.input(qd[k]));
        let inputs = Inputs {
            time: time.node().0,
            q: tq.first().map_or(NONE, |x| x.node().0),
            qd: tqd.first().map_or(NONE, |x| x.node().0),
            rates: qd,
        };
        let tq = SVector::from_array_storage(ArrayStorage([tq]));
        let mut r = l.kinetic(time, &tq, &SVector::from_array_storage(ArrayStorage([tqd])));
        if POTENTIAL {
            r -= l.potential(time, &tq);
        }
        (r.node(), inputs)
    };
    let nodes = tape.nodes()?;
    sweep::second_order::<S, N, CAP, POOL>(&nodes, out, &inputs, m)
}

/// The tape against the jet, which differentiates the same `T` by forward mode: every
/// operation of [`Scalar`] on a tape, its partials and its second partials.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::lagrangian::kinetic_jet;
    use crate::Dual;

    /// Coordinates: as many as a mechanism that takes the tape has.
    const N: usize = 12;

    /// [`kinetic_on`] with `V`, `M` returned.
    fn on_tape<S, L, const K: usize, const POTENTIAL: bool, const CAP: usize, const POOL: usize>(
        l: &L,
        t: S,
        q: &SVector<S, K>,
        qd: &SVector<S, K>,
    ) -> Option<(SMatrix<S, K, K>, SVector<S, K>)>
    where
        S: Scalar<Real = f64> + 'static,
        L: Lagrangian<f64, K>,
    {
        let mut m = SMatrix::from_element(S::zero());
        let f = kinetic_on::<f64, S, L, K, POTENTIAL, CAP, POOL>(l, t, (q, qd), &mut m)?;
        Some((m, f))
    }

    /// [`kinetic`] (the tapes tried) with `V`, `M` returned.
    fn on_tapes<L: Lagrangian<f64, N>>(
        l: &L,
        t: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Option<(SMatrix<f64, N, N>, SVector<f64, N>)> {
        let mut m = SMatrix::zeros();
        let f = kinetic::<f64, f64, L, N, true>(l, t, (q, qd), &mut m)?;
        Some((m, f))
    }

    /// A kinetic energy that uses every operation of [`Scalar`], with constants on either
    /// side, and time where `TIMED` (and a potential, which the tape does not take).
    struct Everything<const TIMED: bool>;

    impl<const TIMED: bool> Lagrangian<f64, N> for Everything<TIMED> {
        const EXPLICIT_TIME: bool = TIMED;
        fn kinetic<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
            let mut e = S::zero();
            for i in 0..N {
                let j = (i + 1) % N;
                e += qd[i] * qd[i] * (q[i].sin() * 0.1 + 1.0) * 0.5;
                e += qd[i] * qd[j] * (q[i] - q[j]).cos() * 0.3;
            }
            e += qd[0] * qd[1] * (q[2] * 0.3).tan() * 0.05;
            e += (q[3] * q[3] + 1.0).sqrt() * qd[3] * qd[3] * 0.2;
            e += (q[4] * 0.1).exp() * qd[4] * qd[5] * 0.1;
            e += (q[5] * q[5] + 2.0).ln() * qd[5] * qd[5];
            e += qd[6].powi(2) * (q[7] * 0.5).cos() + qd[6].powi(3) * 0.01;
            e += q[8] / (q[9] * q[9] + 2.0) * qd[8] * qd[9];
            e += q[10].abs() * qd[10] * qd[10] + (-q[10]).abs() * qd[11] * 0.1;
            e += q[11].atan2(q[0] + 2.0) * qd[11] * qd[0];
            e += (q[1] * q[1] + 3.0).recip() * qd[1] * qd[1];
            e += S::one() / (qd[2] * qd[2] + 4.0) + (qd[2] - 0.5) * (qd[2] + 0.5);
            e += S::from_f64(2.0) - qd[3] / 2.0 - (-qd[4]) * qd[4] * 0.25;
            let (s, c) = (q[6] - q[5]).sin_cos();
            e += qd[7] * (qd[7] * s + qd[8] * c);
            e += (S::from_f64(1.5) * qd[9]).atan2(qd[10] + 3.0) * qd[9];
            // Each operation of a velocity too, where its second partials enter M.
            e += (qd[0] * 0.1).tan() * 0.5 + (qd[1] * qd[1] + 1.0).sqrt();
            e += (qd[2] * qd[2] + 2.0).ln() + (qd[3] * 0.2 + q[3] * 0.1).exp();
            e += (qd[4] * qd[4] + 1.0).recip() + qd[5].atan2(qd[6] + 3.0);
            e += (qd[7] * 0.3).sin() * q[0] + (qd[8] * 0.3).cos() + qd[9].abs() * qd[9];
            e += qd[10] / (qd[11] * qd[11] + 2.0) + (qd[0] * q[1]).sin_cos().1;
            e += (qd[1] * q[2]).sin_cos().0 * 0.5;
            e += qd[3] * qd[3] / 2.0 + qd[4] * qd[5] / S::from_f64(4.0);
            e += qd[6] * qd[7] * S::from_f64(0.7) + q[1] * qd[2] / (qd[3] * q[4] + 3.0);
            // Values shifted and scaled by constants, then multiplied: a wrong value of a
            // sum or a scaling shows in the product's partials.
            let (two, half) = (S::from_f64(2.0), S::from_f64(0.5));
            e += (qd[0] + two) * qd[1] * q[2] + (two + qd[3]) * qd[4] * q[5];
            e += (qd[6] - half) * qd[7] * q[8] + (half - qd[9]) * qd[10] * q[11];
            e += (qd[0] - 1.5) * qd[0] * q[3] + (qd[1] / 4.0) * qd[2] * q[4];
            e += (qd[5] * 2.0) * (qd[6] * 3.0) * q[6] + q[1] * qd[3] / (qd[2] * 2.0 + 3.0);
            if TIMED {
                e += t * qd[0] * q[0] + (t * 0.5).sin() * qd[1] * qd[2];
            }
            e
        }
        fn potential<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>) -> S {
            let mut v = S::zero();
            for i in 0..N {
                v -= q[i].cos() * (9.81 + i as f64);
                v += q[i] * q[(i + 3) % N] * 0.01;
            }
            v += (q[0] * q[1]).exp() * 0.1 + (q[2] * q[2] + 1.0).ln() + q[3].powi(-2) * 0.01;
            v += q[4].atan2(q[5] + 3.0) + (q[6] + 2.0).sqrt() + q[7].tan() * 0.1;
            v + q[8].abs() / (q[9] * q[9] + 1.0) + t * q[10]
        }
    }

    /// A deterministic state in (-1, 1) per coordinate, away from `q[3] = 0`.
    fn state(seed: u64) -> (f64, SVector<f64, N>, SVector<f64, N>) {
        let mut x = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let t = next() * 3.0;
        let mut q = SVector::from_fn(|_, _| next());
        q[3] = 0.5 + q[3].abs();
        (t, q, SVector::from_fn(|_, _| next() * 2.0))
    }

    /// `|a - b|_inf / max(|b|_inf, 1)`.
    fn relative<const R: usize, const C: usize>(
        a: &SMatrix<f64, R, C>,
        b: &SMatrix<f64, R, C>,
    ) -> f64 {
        (a - b).amax() / b.amax().max(1.0)
    }

    /// The worst relative differences of `M` and `f` between the tape (`CAP` nodes) and the
    /// jet over `states` states, asserted below 1e-13.
    fn agree_on<L: Lagrangian<f64, N>, const POTENTIAL: bool, const CAP: usize>(
        l: &L,
        states: u64,
    ) -> Result<(), &'static str> {
        let mut worst = [0.0f64; 2];
        for seed in 0..states {
            let (t, q, qd) = state(seed);
            let (mt, ft) = on_tape::<f64, _, N, POTENTIAL, CAP, 8192>(l, t, &q, &qd)
                .ok_or("T does not fit the tape")?;
            let (mj, fj) = kinetic_jet::<_, _, _, _, POTENTIAL>(l, t, &q, &qd);
            worst[0] = worst[0].max(relative(&mt, &mj));
            worst[1] = worst[1].max(relative(&ft, &fj));
        }
        assert!(worst.iter().all(|&e| e < 1e-13), "worst {worst:?}");
        Ok(())
    }

    /// Both agree to rounding, with and without `V`: measured worst 3.5e-16 (M) and 5.4e-16
    /// (f) over 200 states; bound 1e-13, far under what a wrong partial of any one operation
    /// makes (each of those planted moved M or f by more than 1e-4).
    fn agree<const TIMED: bool, const POTENTIAL: bool>() -> Result<(), &'static str> {
        agree_on::<_, POTENTIAL, 1024>(&Everything::<TIMED>, 200)
    }

    #[test]
    fn the_tape_agrees_with_the_jet() -> Result<(), &'static str> {
        agree::<false, false>()?;
        agree::<false, true>()
    }

    /// The tapes the automatic path tries, smaller first, give the same.
    #[test]
    fn the_tapes_tried_agree_with_the_largest() -> Result<(), &'static str> {
        let l = Everything::<true>;
        for seed in 0..20 {
            let (t, q, qd) = state(seed);
            let large = on_tape::<f64, _, N, true, 1024, 8192>(&l, t, &q, &qd);
            let tried = on_tapes(&l, t, &q, &qd);
            assert_eq!(tried, large);
            tried.ok_or("T does not fit")?;
        }
        Ok(())
    }

    /// A chain of `N` links, as `NLinkPendulum` writes its energies.
    struct Chain<const N: usize>;

    impl<const N: usize> Lagrangian<f64, N> for Chain<N> {
        fn kinetic<S: Scalar<Real = f64>>(
            &self,
            _t: S,
            q: &SVector<S, N>,
            qd: &SVector<S, N>,
        ) -> S {
            let (mut vx, mut vy, mut t) = (S::zero(), S::zero(), S::zero());
            for (j, (th, w)) in q.iter().zip(qd.iter()).enumerate() {
                let (sin, cos) = th.sin_cos();
                let u = *w * (1.0 + 0.1 * j as f64);
                vx += u * cos;
                vy += u * sin;
                t += (vx * vx + vy * vy) * 0.5;
            }
            t
        }
        fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, N>) -> S {
            let (mut y, mut v) = (S::zero(), S::zero());
            for th in q.iter() {
                y -= th.cos();
                v += y * 9.81;
            }
            v
        }
    }

    /// The smaller tape holds a chain of 20 links with its `V` (recorded once per call, not
    /// twice), and a chain of 40 needs the larger.
    #[test]
    fn the_smaller_tape_holds_a_chain_of_twenty() {
        let (q, qd) = (
            SVector::from_fn(|i, _| 0.1 * i as f64),
            SVector::from_element(0.5),
        );
        let c = Chain::<20>;
        assert!(on_tape::<f64, _, 20, true, 384, 1024>(&c, 0.0, &q, &qd).is_some());
        let (q, qd) = (
            SVector::from_fn(|i, _| 0.1 * i as f64),
            SVector::from_element(0.5),
        );
        let c = Chain::<40>;
        assert!(on_tape::<f64, _, 40, true, 384, 1024>(&c, 0.0, &q, &qd).is_none());
        assert!(on_tape::<f64, _, 40, true, 1024, 8192>(&c, 0.0, &q, &qd).is_some());
    }

    /// The chain's `M`, whose squares come in pairs of one range (`vx^2 + vy^2`, added to `M`
    /// in one pass), and its `f` with `V`, agree with the jet's: measured worst 0 (the same
    /// bits) and 4.0e-16 over 50 states; bound 1e-13, as above.
    #[test]
    fn the_chain_on_the_tape_agrees_with_the_jet() -> Result<(), &'static str> {
        agree_on::<_, true, 384>(&Chain::<N>, 50)
    }

    #[test]
    fn the_tape_agrees_with_the_jet_with_time() -> Result<(), &'static str> {
        agree::<true, false>()?;
        agree::<true, true>()
    }

    /// Over one-direction dual numbers (the exact law Jacobian's third derivatives, seeded
    /// along a coordinate or a velocity), both the values and the derivatives agree, with `V`
    /// in every other state: measured worst 6.3e-16 over 100 states; bound 1e-13, as above.
    #[test]
    fn the_tape_agrees_with_the_jet_over_dual_numbers() -> Result<(), &'static str> {
        // Unoptimised, the jet's temporaries over dual numbers (about 3 KB each, every one
        // its own stack slot) outgrow a test thread's 2 MB: run on a larger stack.
        extern crate std;
        std::thread::Builder::new()
            .stack_size(32 << 20)
            .spawn(over_dual_numbers)
            .map_err(|_| "no thread")?
            .join()
            .map_err(|_| "the check panicked")?
    }

    /// The check of [`the_tape_agrees_with_the_jet_over_dual_numbers`].
    fn over_dual_numbers() -> Result<(), &'static str> {
        let l = Everything::<true>;
        let mut worst = 0.0f64;
        for seed in 0..100 {
            let (t, q, qd) = state(seed);
            let k = (seed as usize / 2) % N;
            let seeded = |v: &SVector<f64, N>, on: bool| {
                SVector::<Dual<f64, 1>, N>::from_fn(|i, _| {
                    if on && i == k {
                        Dual::variable(v[i], 0)
                    } else {
                        Dual::constant(v[i])
                    }
                })
            };
            let velocity = seed % 2 == 1;
            let (dq, dqd) = (seeded(&q, !velocity), seeded(&qd, velocity));
            let dt = Dual::constant(t);
            let (taped, (mj, fj)) = if seed % 4 < 2 {
                (
                    on_tape::<_, _, N, false, 1024, 8192>(&l, dt, &dq, &dqd),
                    kinetic_jet::<_, _, _, _, false>(&l, dt, &dq, &dqd),
                )
            } else {
                (
                    on_tape::<_, _, N, true, 1024, 8192>(&l, dt, &dq, &dqd),
                    kinetic_jet::<_, _, _, _, true>(&l, dt, &dq, &dqd),
                )
            };
            let (mt, ft) = taped.ok_or("T does not fit the tape")?;
            let parts = |m: &SMatrix<Dual<f64, 1>, N, N>, f: &SVector<Dual<f64, 1>, N>| {
                (
                    m.map(|x| x.re),
                    m.map(|x| x.eps[0]),
                    f.map(|x| x.re),
                    f.map(|x| x.eps[0]),
                )
            };
            let (a, b) = (parts(&mt, &ft), parts(&mj, &fj));
            worst = worst
                .max(relative(&a.0, &b.0))
                .max(relative(&a.1, &b.1))
                .max(relative(&a.2, &b.2))
                .max(relative(&a.3, &b.3));
        }
        assert!(worst < 1e-13, "worst {worst:e}");
        Ok(())
    }

    /// A recorded number behaves as a plain one where a `T` looks at it: its value, its
    /// equality, whether it is zero, how it prints.
    #[test]
    fn a_recorded_number_reads_as_its_value() {
        let mut storage = heapless::Vec::<Node<f64>, 16>::new();
        let tape = Tape::new(&mut storage, true);
        let x = tape.input(1.5);
        let y = x * 2.0 - 1.0;
        assert_eq!(Scalar::value(y), 2.0);
        assert!(y == Taped::constant(2.0) && y != x && x == tape.input(1.5));
        // Zero only as a constant: a recorded zero still carries a derivative.
        assert!(!num_traits::Zero::is_zero(&(x * 2.0 - 3.0)));
        assert!(
            !num_traits::Zero::is_zero(&y)
                && num_traits::Zero::is_zero(&<Taped<f64, 16> as num_traits::Zero>::zero())
        );
        assert!(!num_traits::Zero::is_zero(&Taped::<f64, 16>::constant(1.0)));
        let mut text = heapless::String::<64>::new();
        core::fmt::write(&mut text, format_args!("{y:?}")).ok();
        assert_eq!(text.as_str(), "Taped(2.0 = 2.0 x node 0)");
    }

    /// A `T` of more nodes than a tape holds is refused (the caller falls back to the jet),
    /// never half-recorded.
    #[test]
    fn a_tape_too_small_refuses() {
        let l = Everything::<false>;
        let (t, q, qd) = state(1);
        assert!(on_tape::<f64, _, N, true, 64, 8192>(&l, t, &q, &qd).is_none());
        assert!(on_tape::<f64, _, N, true, 1024, 16>(&l, t, &q, &qd).is_none());
        assert!(on_tapes(&l, t, &q, &qd).is_some());
    }
}
