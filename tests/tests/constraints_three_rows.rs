//! Three coupled constraint rows (three planes through a point in space, not at right angles
//! to each other): the projection's mass-weighted Newton step is exact on linear rows, so it
//! lands on the point in one iteration and leaves the velocity tangent to all three rows.
//! This exercises the Schur complement's Cholesky factor beyond two rows, where its off-
//! diagonal entries combine earlier columns.

use lagrange_core::nalgebra::{Matrix3, SVector, Vector3};
use lagrange_core::{Constraints, Error, EulerLagrange, Lagrangian, Projection, Scalar, State};

/// A unit point mass in space, free.
struct Point;

impl Lagrangian<f64, 3> for Point {
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 3>, v: &SVector<S, 3>) -> S {
        // By iterator, not `v.dot(v)`: the automatic path's scalars need not be `'static`,
        // which nalgebra's arithmetic methods ask of theirs.
        v.iter().fold(S::zero(), |sum, &x| sum + x * x) * S::from_f64(0.5)
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 3>) -> S {
        S::from_f64(0.0)
    }
}

/// `A q = b`: three planes whose normals (the rows of `A`) are far from orthogonal.
struct Planes;

fn normals() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.5, 0.2, 0.3, 1.0, 0.4, 0.1, 0.6, 1.0)
}

impl Constraints<f64, 3, 3> for Planes {
    fn position_residual(&self, q: &Vector3<f64>) -> Vector3<f64> {
        normals() * q - Vector3::new(1.0, 2.0, 3.0)
    }
    fn jacobian(&self, _q: &Vector3<f64>) -> Matrix3<f64> {
        normals()
    }
    fn velocity_product(&self, _q: &Vector3<f64>, _qd: &Vector3<f64>) -> Vector3<f64> {
        Vector3::zeros()
    }
}

/// One Newton iteration reaches the point to rounding (bound 1e-12, measured about 1e-15),
/// and the velocity's normal components are removed to rounding.
#[test]
fn linear_rows_are_met_in_one_iteration() -> Result<(), Error> {
    let point = EulerLagrange::new(Point);
    let s = State::new(0.0, [0.0, 0.0, 0.0], [1.0, -2.0, 0.5]);
    let projected = Projection::new(1e-12, 1)?.project(&point, &Planes, &s)?;
    let residual = Planes.position_residual(&projected.q).amax();
    let normal_speed = (normals() * projected.qd).amax();
    assert!(residual < 1e-12, "residual {residual:e}");
    assert!(normal_speed < 1e-12, "normal speed {normal_speed:e}");
    Ok(())
}
