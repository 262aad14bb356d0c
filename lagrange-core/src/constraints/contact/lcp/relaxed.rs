//! [`Delassus::relaxed`]: projected Gauss-Seidel on the candidate rows, the answer that
//! always comes where the exact method may not (a degenerate set it cycles on).

use super::{Complementary, Delassus, Row};
use crate::nalgebra::SVector;
use crate::Real;

impl<T: Real, const N: usize, const C: usize> Delassus<T, N, C> {
    /// Multipliers within the rows' bounds that lower the program of
    /// [`Delassus::complementary`] (`lambda^T W lambda / 2 + b^T lambda`) from `lambda = 0`:
    /// `sweeps` sweeps of projected Gauss-Seidel over the candidates in order, each row's
    /// multiplier set to the minimum of the program along it, clamped to its bounds. Each
    /// such change lowers the program or leaves it, so the value is never above zero: as
    /// impulses from velocities `b` (targets zero), they never add kinetic energy. The rows
    /// are `active` where the multiplier is inside its bounds and not zero. Approximate (the
    /// error shrinks with the sweeps at a rate set by how far `W` is from diagonal), but it
    /// always returns, and in `sweeps R^2` multiply-adds (`R` candidates): the fallback of
    /// a real-time solve. A row of no mobility (`W_ii` zero) stays at zero.
    #[must_use]
    pub fn relaxed(
        &self,
        b: &SVector<T, C>,
        kinds: &[Row<T>; C],
        sweeps: u32,
    ) -> Complementary<T, C> {
        let mut lambda = SVector::<T, C>::zeros();
        // The candidates as listed (as the exact solve reads them), not a scan of all `C`
        // rows' flags in each sum of each sweep.
        for _ in 0..sweeps {
            for i in self.listed.rows() {
                let diagonal = self.w[(i, i)];
                // Not positive (or NaN): a row that no impulse moves.
                if diagonal.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
                    continue;
                }
                let a = self
                    .listed
                    .rows()
                    .fold(b[i], |a, k| a + self.w[(i, k)] * lambda[k]);
                let (lo, hi) = kinds[i].bounds();
                lambda[i] = (lambda[i] - a / diagonal).max(lo).min(hi);
            }
        }
        let active = core::array::from_fn(|i| {
            let (lo, hi) = kinds[i].bounds();
            self.candidate[i] && lambda[i] != T::zero() && lambda[i] > lo && lambda[i] < hi
        });
        Complementary {
            lambda,
            active,
            passes: sweeps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Delassus, Row};
    use crate::nalgebra::{SMatrix, SVector};
    use crate::Error;

    /// The program's value `lambda^T W lambda / 2 + b^T lambda`.
    fn value<const N: usize, const C: usize>(
        d: &Delassus<f64, N, C>,
        lambda: &SVector<f64, C>,
        b: &SVector<f64, C>,
    ) -> f64 {
        (lambda.transpose() * d.w * lambda)[0] / 2.0 + b.dot(lambda)
    }

    /// The corner of the exact method's tests (a floor, a wall and a row that depends on
    /// both, one unit mass): within the bounds, never above zero whatever the sweeps, and
    /// after 60 sweeps the exact method's value to 1e-12 (the error shrinks geometrically);
    /// a bounded row stays within its bound; a candidate of no mobility stays at zero. (Where
    /// that candidate approaches, `b < 0`, no impulse can stop it and the exact method
    /// refuses the set: the next test.)
    #[test]
    fn lowers_the_program_within_the_bounds() -> Result<(), Error> {
        let j = SMatrix::<f64, 4, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0);
        let mut d = Delassus::new(&j, |_| Ok(()), &[true; 4])?;
        let kinds = [
            Row::Unilateral,
            Row::Bounded(0.5),
            Row::Unilateral,
            Row::Unilateral,
        ];
        for b in [
            SVector::<f64, 4>::new(-1.0, -2.0, -3.0, 1.0),
            SVector::<f64, 4>::new(-1.0, 2.0, 1.0, 0.0),
            SVector::<f64, 4>::new(1.0, 2.0, 3.0, 1.0),
            SVector::<f64, 4>::new(-3.0, -0.5, -1.0, 2.0),
        ] {
            for sweeps in [0, 1, 2, 5] {
                let r = d.relaxed(&b, &kinds, sweeps);
                assert!(value(&d, &r.lambda, &b) <= 0.0, "{b:?}, {sweeps}: {r:?}");
                assert!(r.lambda[0] >= 0.0 && r.lambda[2] >= 0.0, "{r:?}");
                assert!(r.lambda[1].abs() <= 0.5 && r.lambda[3] == 0.0, "{r:?}");
            }
            let exact = d.complementary(&b, &kinds)?;
            let relaxed = d.relaxed(&b, &kinds, 60);
            let (v, best) = (value(&d, &relaxed.lambda, &b), value(&d, &exact.lambda, &b));
            assert!((v - best).abs() <= 1e-12, "{b:?}: {v} against {best}");
        }
        Ok(())
    }

    /// A contact of no mobility that approaches (`b < 0`): no multipliers meet the
    /// conditions, and the exact method says so at once (`NoConvergence` at its third pass:
    /// the floor solved, the row joins, its ray has no end;
    /// not after its cap of `4 C + 4`), where the relaxed one still returns, that row at zero
    /// and the others' program lowered.
    #[test]
    fn a_set_with_no_solution_is_refused_at_once() -> Result<(), Error> {
        let j = SMatrix::<f64, 2, 2>::new(0.0, 1.0, 0.0, 0.0);
        let mut d = Delassus::new(&j, |_| Ok(()), &[true; 2])?;
        let b = SVector::<f64, 2>::new(-1.0, -1.0);
        let kinds = [Row::Unilateral; 2];
        assert_eq!(
            d.complementary_from(&b, &kinds, &[false; 2]),
            Err(Error::NoConvergence { iterations: 3 })
        );
        let r = d.relaxed(&b, &kinds, 4);
        assert_eq!((r.lambda[0], r.lambda[1]), (1.0, 0.0), "{r:?}");
        Ok(())
    }

    /// A row is active where its multiplier is strictly inside its bounds and not zero: a
    /// contact that pushes, not a friction row held at either bound, not a row that is no
    /// candidate (four independent rows of one unit mass in four freedoms, `W = I`, so one
    /// sweep lands each at its clamped minimum `-b`).
    #[test]
    fn active_rows_are_inside_their_bounds() -> Result<(), Error> {
        let j = SMatrix::<f64, 4, 4>::identity();
        let d = Delassus::new(&j, |_| Ok(()), &[true, true, true, false])?;
        let kinds = [
            Row::Unilateral,
            Row::Bounded(0.5),
            Row::Bounded(0.5),
            Row::Bounded(0.5),
        ];
        let b = SVector::<f64, 4>::new(-1.0, -5.0, 5.0, -0.1);
        let r = d.relaxed(&b, &kinds, 1);
        assert_eq!(r.lambda, SVector::<f64, 4>::new(1.0, 0.5, -0.5, 0.0));
        assert_eq!(r.active, [true, false, false, false]);
        Ok(())
    }

    /// Rows that are not candidates take no part, and no row is active at zero.
    #[test]
    fn only_candidates_take_part() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        let d = Delassus::new(&j, |_| Ok(()), &[true, false, true])?;
        let b = SVector::<f64, 3>::new(-1.0, -1.0, 2.0);
        let r = d.relaxed(&b, &[Row::Unilateral; 3], 10);
        assert_eq!(r.lambda[1], 0.0);
        assert_eq!(r.active, [true, false, false]);
        assert!((r.lambda[0] - 1.0).abs() < 1e-15, "{r:?}");
        Ok(())
    }
}
