//! `Shape::distance` and `Shape::ray` against exact figures (a circle, a box, a capsule's end
//! cap, a rounded box's corner) and, over random shapes and rays, against each other and an
//! independent march: a hit lies on the surface (distance zero to rounding) with the surface
//! positive just before it and the normal the distance's gradient; a miss has every point of
//! the ray outside. Both precisions.

use lagrange_core::links::Pose;
use lagrange_core::{Error, Real};
use lagrange_tests::{for_f32_and_f64, pick, Rng};
use lagrange_world::Shape;

fn v<T: Real>(x: f64, y: f64) -> [T; 2] {
    [T::from_f64(x), T::from_f64(y)]
}

fn exact_figures<T: Real>() -> Result<(), Error> {
    let tol = pick::<T>(1e-6, 1e-14);
    let near = |a: T, b: f64| (a.to_f64() - b).abs() < tol;
    let circle = Shape::circle(T::HALF)?.placed(&Pose {
        origin: v(1.0, 1.0),
        angle: T::zero(),
    });
    assert!(near(circle.distance(v(4.0, 5.0)), 4.5));
    assert!(near(circle.distance(v(1.0, 1.25)), -0.25));
    let hit = circle
        .ray(v(-2.0, 1.0), v(2.0, 0.0), T::from_f64(10.0))
        .ok_or(Error::NoConvergence { iterations: 0 })?;
    // From x = -2 at 2 m per unit of t to x = 0.5: t = 1.25, normal -x.
    assert!(
        near(hit.t, 1.25) && near(hit.normal[0], -1.0) && near(hit.point[0], 0.5),
        "{hit:?}"
    );
    assert!(circle.ray(v(-2.0, 1.0), v(2.0, 0.0), T::one()).is_none());
    assert!(circle
        .ray(v(-2.0, 2.0), v(1.0, 0.0), T::from_f64(10.0))
        .is_none());
    let inside = circle
        .ray(v(1.1, 1.0), v(1.0, 0.0), T::one())
        .ok_or(Error::NoConvergence { iterations: 0 })?;
    assert_eq!((inside.t, inside.normal), (T::zero(), [T::zero(); 2]));
    let boxed = Shape::rectangle(T::from_f64(2.0), T::one())?;
    assert!(near(boxed.distance(v(0.3, 0.2)), -0.3));
    assert!(near(boxed.distance(v(4.0, 4.5)), 5.0));
    let hit = boxed
        .ray(v(0.2, 3.0), v(0.0, -1.0), T::from_f64(10.0))
        .ok_or(Error::NoConvergence { iterations: 0 })?;
    assert!(near(hit.t, 2.5) && near(hit.normal[1], 1.0), "{hit:?}");
    // A capsule's end cap: half length 1, radius 0.5, hit along its axis from the right.
    let capsule = Shape::capsule(T::one(), T::HALF)?;
    let hit = capsule
        .ray(v(3.0, 0.0), v(-1.0, 0.0), T::from_f64(10.0))
        .ok_or(Error::NoConvergence { iterations: 0 })?;
    assert!(near(hit.t, 1.5) && near(hit.normal[0], 1.0), "{hit:?}");
    // A rounded box's corner, along its diagonal: the corner (1, 0.5) plus 0.25 outwards.
    let rounded = Shape::rectangle(T::from_f64(2.0), T::one())?.rounded(T::from_f64(0.25))?;
    let far = 3.0;
    let hit = rounded
        .ray(v(1.0 + far, 0.5 + far), v(-1.0, -1.0), T::from_f64(10.0))
        .ok_or(Error::NoConvergence { iterations: 0 })?;
    let expected = far - 0.25 / 2.0_f64.sqrt();
    assert!(near(hit.t, expected), "{hit:?} against {expected}");
    assert!(near(
        rounded.distance(v(1.0 + far, 0.5 + far)),
        far * 2.0_f64.sqrt() - 0.25
    ));
    // A ray that starts inside meets the shape at its start, if its range holds zero: a
    // range below zero or not a number holds nothing.
    let inside = v(0.5, 0.5);
    let at_start = rounded.ray(inside, v(1.0, 0.0), T::zero());
    assert_eq!(at_start.map(|h| h.t), Some(T::zero()));
    for t_max in [-1.0, f64::NAN] {
        assert_eq!(
            rounded.ray(inside, v(1.0, 0.0), T::from_f64(t_max)),
            None,
            "{t_max}"
        );
    }
    Ok(())
}

/// 2,000 random rays at random shapes (circles, capsules, boxes, rounded or not, turned and
/// moved): a hit's point is on the surface (|distance| below 1e-9 of the sizes in f64, 1e-4 in
/// f32) and outside just before it; its normal is the gradient of the distance there (central
/// differences, to 1e-4; not within a few steps of a sharp corner, where it has none); a miss
/// leaves every one of 400 points along the ray outside (the ray's start outside). Rays are
/// aimed at the shape give or take 0.6 rad: about 40% hit.
fn rays_agree_with_distances<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(343);
    let tol = pick::<T>(1e-4, 1e-9);
    let (mut hits, mut misses) = (0, 0);
    for case in 0..2000 {
        let shape = match (rng.unit() * 3.0) as usize {
            0 => Shape::circle(rng.uniform(0.1, 1.0))?,
            1 => Shape::capsule(rng.uniform(0.1, 1.0), rng.uniform(0.05, 0.5))?,
            _ => Shape::rectangle(rng.uniform(0.2, 2.0), rng.uniform(0.2, 2.0))?,
        };
        let shape = if rng.unit() < 0.3 {
            shape.rounded(rng.uniform(0.0, 0.3))?
        } else {
            shape
        };
        let shape = shape.placed(&Pose {
            origin: v(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)),
            angle: rng.uniform(-3.2, 3.2),
        });
        let origin = v::<T>(rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0));
        if shape.distance(origin) <= T::zero() {
            continue;
        }
        // Aimed at the shape's centre, give or take 0.6 rad: about half hit.
        let centre = shape.vertices().iter().fold([0.0; 2], |c, p| {
            [c[0] + p[0].to_f64(), c[1] + p[1].to_f64()]
        });
        let count = shape.vertices().len() as f64;
        let aim =
            (centre[1] / count - origin[1].to_f64()).atan2(centre[0] / count - origin[0].to_f64());
        let angle: f64 = aim + rng.uniform::<f64>(-0.6, 0.6);
        let direction = v::<T>(angle.cos(), angle.sin());
        let t_max = T::from_f64(10.0);
        match shape.ray(origin, direction, t_max) {
            Some(hit) => {
                hits += 1;
                assert!(
                    shape.distance(hit.point).to_f64().abs() < tol,
                    "case {case}: {hit:?}"
                );
                let before = [
                    origin[0] + direction[0] * (hit.t - T::from_f64(1e-3)),
                    origin[1] + direction[1] * (hit.t - T::from_f64(1e-3)),
                ];
                assert!(
                    shape.distance(before) > T::zero(),
                    "case {case}: inside before {hit:?}"
                );
                let h = pick::<T>(1e-3, 1e-6);
                // Where the surface turns a sharp corner (within a few h of one), the
                // gradient of the distance is not defined there: skipped.
                let corner = shape.vertices().iter().any(|w| {
                    let d = ((w[0] - hit.point[0]).to_f64().powi(2)
                        + (w[1] - hit.point[1]).to_f64().powi(2))
                    .sqrt();
                    d < shape.radius().to_f64() + 4.0 * h
                });
                let grad = [0, 1].map(|k| {
                    let (mut a, mut b) = (hit.point, hit.point);
                    a[k] += T::from_f64(h);
                    b[k] -= T::from_f64(h);
                    (shape.distance(a) - shape.distance(b)).to_f64() / (2.0 * h)
                });
                let off = (grad[0] - hit.normal[0].to_f64()).abs()
                    + (grad[1] - hit.normal[1].to_f64()).abs();
                assert!(
                    corner || off < pick::<T>(1e-2, 1e-4),
                    "case {case}: normal {hit:?} against {grad:?}"
                );
            }
            None => {
                misses += 1;
                for k in 0..=400 {
                    let t = T::from_f64(10.0 * k as f64 / 400.0);
                    let p = [origin[0] + direction[0] * t, origin[1] + direction[1] * t];
                    assert!(
                        shape.distance(p) > T::zero(),
                        "case {case}: a miss, but inside at t = {t:?}"
                    );
                }
            }
        }
    }
    println!("{hits} hits, {misses} misses");
    assert!(hits > 200 && misses > 200);
    Ok(())
}

for_f32_and_f64!(exact_figures, rays_agree_with_distances);
