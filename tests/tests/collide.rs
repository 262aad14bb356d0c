//! The narrow phase (`lagrange_world::collide`, `collide_half_plane`) against exact figures
//! (two circles, boxes resting on boxes, capsules on boxes, a turned crate on the floor) and,
//! over random pairs of every kind of shape at random poses, against an independent measure:
//! moving the second shape back along the normal by its gap makes the two just touch, as
//! point clouds sampled over both shapes say; a manifold has points exactly when the
//! sampled distance is within the margin; swapping the shapes negates the normal and keeps
//! the gaps. Both precisions.

use lagrange_core::links::Pose;
use lagrange_core::{Error, Real};
use lagrange_tests::{for_f32_and_f64, pick, Rng};
use lagrange_world::{collide, collide_half_plane, HalfPlane, Manifold, Shape};

fn pose<T: Real>(x: f64, y: f64, angle: f64) -> Pose<T> {
    Pose {
        origin: [T::from_f64(x), T::from_f64(y)],
        angle: T::from_f64(angle),
    }
}

fn gaps<T: Real>(m: &Manifold<T>) -> Vec<f64> {
    let mut g: Vec<f64> = m.points().iter().map(|p| p.gap.to_f64()).collect();
    g.sort_by(f64::total_cmp);
    g
}

/// Two circles: the gap is the distance of the centres less the radii, along the line of
/// centres, to rounding (4 ulps of the sizes); coincident centres push straight up.
fn circles<T: Real>() -> Result<(), Error> {
    let a = Shape::circle(T::from_f64(0.5))?.placed(&pose(1.0, 2.0, 0.0));
    let b = Shape::circle(T::from_f64(0.25))?.placed(&pose(1.6, 2.8, 0.3));
    let m = collide(&a, &b, T::from_f64(0.5));
    let tol = 4.0 * T::EPSILON.to_f64() * 4.0;
    assert_eq!(m.points().len(), 1);
    assert!((m.points()[0].gap.to_f64() - 0.25).abs() < tol, "{m:?}");
    assert!((m.normal[0].to_f64() - 0.6).abs() < tol && (m.normal[1].to_f64() - 0.8).abs() < tol);
    // Midway between the surfaces: 0.5 + 0.125 along the normal from a's centre.
    let p = m.points()[0].point;
    assert!((p[0].to_f64() - (1.0 + 0.625 * 0.6)).abs() < tol, "{p:?}");
    assert!(collide(&a, &b, T::from_f64(0.2)).points().is_empty());
    let same = collide(
        &a,
        &Shape::circle(T::one())?.placed(&pose(1.0, 2.0, 0.0)),
        T::zero(),
    );
    assert_eq!(same.normal, [T::zero(), T::one()]);
    assert_eq!(gaps(&same), [-1.5]);
    Ok(())
}

/// A unit box on a 4 m wide one, 1 mm into it: two points 1 mm deep at its lower corners,
/// normal up; turned by 0.01 rad, the lower corner 0.5 sin 0.01 lower than the centre line
/// and the other that much higher (4 mm apart: one point); lifted 6 mm more, with a margin
/// of 2 cm, two speculative points (2.5e-5 and 1.0e-2 m apart).
fn boxes<T: Real>() -> Result<(), Error> {
    let floor = Shape::rectangle(T::from_f64(4.0), T::one())?;
    let unit = Shape::rectangle(T::one(), T::one())?;
    let tol = pick::<T>(1e-6, 1e-14);
    let m = collide(&floor, &unit.placed(&pose(0.3, 0.999, 0.0)), T::zero());
    let g = gaps(&m);
    assert!(
        g.len() == 2 && g.iter().all(|g| (g + 0.001).abs() < tol),
        "{m:?}"
    );
    let (s, c) = 0.01_f64.sin_cos();
    let low = 0.999 - 0.5 * c - 0.5 * s - 0.5;
    let high = 0.999 - 0.5 * c + 0.5 * s - 0.5;
    let m = collide(&floor, &unit.placed(&pose(0.0, 0.999, 0.01)), T::zero());
    assert_eq!(m.points().len(), 1, "{m:?}");
    assert!((gaps(&m)[0] - low).abs() < tol, "{m:?} against {low}");
    let m = collide(
        &floor,
        &unit.placed(&pose(0.0, 1.005, 0.01)),
        T::from_f64(0.02),
    );
    let g = gaps(&m);
    assert!(
        g.len() == 2 && (g[0] - (low + 0.006)).abs() < tol && (g[1] - (high + 0.006)).abs() < tol,
        "{g:?}"
    );
    Ok(())
}

/// A capsule (half length 0.5, radius 0.1) lying on a box 2 cm into it: two points 2 cm
/// deep under its two ends; standing on its end: one point.
fn capsules<T: Real>() -> Result<(), Error> {
    let floor = Shape::rectangle(T::from_f64(4.0), T::one())?;
    let capsule = Shape::capsule(T::HALF, T::from_f64(0.1))?;
    let tol = pick::<T>(1e-6, 1e-14);
    let m = collide(&floor, &capsule.placed(&pose(0.0, 0.58, 0.0)), T::zero());
    let g = gaps(&m);
    assert!(
        g.len() == 2 && g.iter().all(|g| (g + 0.02).abs() < tol),
        "{m:?}"
    );
    let xs: Vec<f64> = m.points().iter().map(|p| p.point[0].to_f64()).collect();
    assert!(xs.iter().any(|x| (x + 0.5).abs() < tol) && xs.iter().any(|x| (x - 0.5).abs() < tol));
    let m = collide(
        &floor,
        &capsule.placed(&pose(0.0, 1.08, core::f64::consts::FRAC_PI_2)),
        T::zero(),
    );
    let g = gaps(&m);
    assert!(g.len() == 1 && (g[0] + 0.02).abs() < tol, "{m:?}");
    Ok(())
}

/// A crate turned by 0.1 rad on the floor: the lower corner at `y - 0.25 (cos + sin)`, one
/// point; a capsule on its side there: two; the ids name the vertices.
fn half_planes<T: Real>() -> Result<(), Error> {
    let floor = HalfPlane::new([T::zero(), T::from_f64(2.0)], T::zero())?;
    let crate_ = Shape::rectangle(T::HALF, T::HALF)?.placed(&pose(0.0, 0.27, 0.1));
    let m = collide_half_plane(&floor, &crate_, T::from_f64(0.01));
    let exact = 0.27 - 0.25 * (0.1_f64.cos() + 0.1_f64.sin());
    assert_eq!(m.points().len(), 1);
    assert!(
        (m.points()[0].gap.to_f64() - exact).abs() < pick::<T>(1e-6, 1e-15),
        "{m:?}"
    );
    assert_eq!(m.points()[0].id, 0);
    let capsule = Shape::capsule(T::HALF, T::from_f64(0.1))?.placed(&pose(0.0, 0.09, 0.0));
    assert_eq!(
        gaps(&collide_half_plane(&floor, &capsule, T::zero())).len(),
        2
    );
    assert!(HalfPlane::new([T::zero(); 2], T::zero()).is_err());
    assert!(HalfPlane::new([T::one(), T::zero()], T::from_f64(f64::NAN)).is_err());
    Ok(())
}

/// A random shape of size about 0.2 to 1: a circle, a capsule, a box, a random convex polygon
/// (points on an ellipse at sorted angles), any of them rounded or not.
fn random_shape<T: Real>(rng: &mut Rng) -> Result<Shape<T>, Error> {
    let kind = (rng.unit() * 4.0) as usize;
    let shape = match kind {
        0 => Shape::circle(rng.uniform(0.1, 0.5))?,
        1 => Shape::capsule(rng.uniform(0.1, 0.5), rng.uniform(0.05, 0.3))?,
        2 => Shape::rectangle(rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.0))?,
        _ => {
            let n = 3 + (rng.unit() * 6.0) as usize;
            let mut angles: Vec<f64> = (0..n)
                .map(|k| (k as f64 + rng.unit() * 0.8) * core::f64::consts::TAU / n as f64)
                .collect();
            angles.sort_by(f64::total_cmp);
            let (rx, ry) = (rng.uniform::<f64>(0.2, 0.6), rng.uniform::<f64>(0.2, 0.6));
            let v: Vec<[T; 2]> = angles
                .iter()
                .map(|a| [T::from_f64(rx * a.cos()), T::from_f64(ry * a.sin())])
                .collect();
            Shape::polygon(&v)?
        }
    };
    if kind >= 2 && rng.unit() < 0.3 {
        shape.rounded(rng.uniform(0.02, 0.1))
    } else {
        Ok(shape)
    }
}

/// Points on a shape's boundary every `step` or closer: each edge of the core moved out by
/// the radius along its normal, and the arc of the radius at each vertex between its edges'
/// normals (a circle's whole circle).
fn cloud<T: Real>(s: &Shape<T>, step: f64) -> Vec<[f64; 2]> {
    let f = |p: [T; 2]| [p[0].to_f64(), p[1].to_f64()];
    let v: Vec<[f64; 2]> = s.vertices().iter().map(|&p| f(p)).collect();
    let normals: Vec<[f64; 2]> = s.normals().iter().map(|&p| f(p)).collect();
    let r = s.radius().to_f64();
    let n = v.len();
    let mut out = Vec::new();
    let mut arc = |c: [f64; 2], from: f64, sweep: f64| {
        let k = ((sweep * r / step).ceil() as usize).max(1);
        for j in 0..=k {
            let a = from + sweep * j as f64 / k as f64;
            out.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
        }
    };
    if n == 1 {
        arc(v[0], 0.0, core::f64::consts::TAU);
        return out;
    }
    for i in 0..n {
        let (prev, next) = (normals[(i + n - 1) % n], normals[i]);
        let from = prev[1].atan2(prev[0]);
        let sweep = (next[1].atan2(next[0]) - from).rem_euclid(core::f64::consts::TAU);
        if r > 0.0 {
            arc(v[i], from, sweep);
        }
    }
    for i in 0..n {
        let (a, b, m) = (v[i], v[(i + 1) % n], normals[i]);
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let k = (len / step).ceil().max(1.0) as usize;
        for j in 0..=k {
            let t = j as f64 / k as f64;
            out.push([
                a[0] + (b[0] - a[0]) * t + r * m[0],
                a[1] + (b[1] - a[1]) * t + r * m[1],
            ]);
        }
    }
    out
}

fn cloud_distance(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let mut best = f64::INFINITY;
    for p in a {
        for q in b {
            best = best.min((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2));
        }
    }
    best.sqrt()
}

/// 300 random pairs (seeded) at random poses within reach of each other, margin 0.1: with
/// the second shape moved back along the normal by its smallest gap the two clouds (spacing
/// 5 mm) come within 5 mm of each other (they just touch: the sampled distance of touching
/// shapes is at most the spacing); a manifold has points exactly when the shapes' sampled
/// distance is within the margin (beyond 5 mm of it either way); the pair swapped has the
/// opposite normal and the same gaps (to 1e-12 in f64, 1e-4 in f32).
fn random_pairs_touch_when_moved_by_their_gap<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(34);
    let (step, margin) = (5e-3, 0.1);
    let mut touching = 0;
    for case in 0..300 {
        let a = random_shape::<T>(&mut rng)?.placed(&pose(0.0, 0.0, rng.uniform(-3.2, 3.2)));
        let b = random_shape::<T>(&mut rng)?;
        let b = b.placed(&pose(
            rng.uniform(-1.2, 1.2),
            rng.uniform(-1.2, 1.2),
            rng.uniform(-3.2, 3.2),
        ));
        let m = collide(&a, &b, T::from_f64(margin));
        let distance = cloud_distance(&cloud(&a, step), &cloud(&b, step));
        match m.gap() {
            None => assert!(
                distance > margin - step,
                "case {case}: no points at {distance}: {m:?}"
            ),
            Some(gap) => {
                touching += 1;
                assert!(
                    distance <= margin + step,
                    "case {case}: points at {distance}: {m:?}"
                );
                let back = gap.to_f64();
                let moved = b.placed(&Pose {
                    origin: [
                        T::from_f64(-back) * m.normal[0],
                        T::from_f64(-back) * m.normal[1],
                    ],
                    angle: T::zero(),
                });
                let after = cloud_distance(&cloud(&a, step), &cloud(&moved, step));
                assert!(
                    after <= step,
                    "case {case}: gap {back}, then apart by {after}: {m:?}"
                );
                let swapped = collide(&b, &a, T::from_f64(margin));
                let tol = pick::<T>(1e-4, 1e-12);
                assert!(
                    (swapped.normal[0] + m.normal[0]).to_f64().abs() < tol
                        && (swapped.normal[1] + m.normal[1]).to_f64().abs() < tol,
                    "case {case}: {m:?} against {swapped:?}\na {a:?}\nb {b:?}"
                );
                let (g, h) = (gaps(&m), gaps(&swapped));
                assert!(
                    g.len() == h.len() && g.iter().zip(&h).all(|(x, y)| (x - y).abs() < tol),
                    "case {case}: {g:?} against {h:?}"
                );
            }
        }
    }
    println!("{} of 300 pairs within the margin", touching);
    assert!(touching > 100);
    Ok(())
}

/// Each constructor refuses what is not a shape, by name: a polygon of fewer than 3 or more
/// than 8 vertices, wound clockwise, not convex, with a vertex on its neighbours' edge or two
/// alike, not finite or so large that its edge products overflow; a radius, width, height or
/// half length not positive and finite. A rounded box keeps its core and adds the radius.
fn shapes_are_validated<T: Real>() -> Result<(), Error> {
    let p = |v: &[[f64; 2]]| {
        let v: Vec<[T; 2]> = v.iter().map(|p| p.map(T::from_f64)).collect();
        Shape::polygon(&v)
    };
    let refused = |r: Result<Shape<T>, Error>, name: &str| {
        assert!(
            matches!(r, Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{name}: {r:?}"
        );
    };
    let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    assert_eq!(p(&square)?.vertices().len(), 4);
    refused(p(&square[..2]), "vertices");
    refused(p(&[[0.0, 0.0]; 9]), "vertices");
    let clockwise: Vec<[f64; 2]> = square.iter().rev().copied().collect();
    refused(p(&clockwise), "vertices");
    refused(
        p(&[[0.0, 0.0], [1.0, 0.0], [0.2, 0.2], [0.0, 1.0]]),
        "vertices",
    );
    refused(
        p(&[[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        "vertices",
    );
    refused(
        p(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        "vertices",
    );
    // Stars whose every turn is to the left, twice round: the pentagram, the heptagram
    // {7/2}, and the square wound twice.
    let star = |n: usize, step: usize| -> Vec<[f64; 2]> {
        (0..n)
            .map(|k| {
                let a = core::f64::consts::TAU * (k * step) as f64 / n as f64;
                [a.cos(), a.sin()]
            })
            .collect()
    };
    refused(p(&star(5, 2)), "vertices");
    refused(p(&star(7, 2)), "vertices");
    let twice: Vec<[f64; 2]> = square.iter().chain(&square).copied().collect();
    refused(p(&twice), "vertices");
    // A triangle far from the unit's scale, whose products stay within the scalar: kept;
    // further, refused for the scalar's limits, not as a shape that is not convex (which
    // two vertices alike are).
    let scaled = |k: f64| [[0.0, 0.0], [k, 0.0], [0.0, k]];
    let far = pick::<T>(1e15, 1e100);
    assert_eq!(p(&scaled(far))?.vertices().len(), 3);
    assert_eq!(p(&scaled(1.0 / far))?.vertices().len(), 3);
    let reason = |r: Result<Shape<T>, Error>| match r {
        Err(Error::InvalidParameter { reason, .. }) => reason,
        _ => "",
    };
    let beyond = pick::<T>(1e25, 1e200);
    for k in [beyond, 1.0 / beyond] {
        assert!(
            reason(p(&scaled(k))).contains("too long or too short"),
            "{k:e}"
        );
    }
    let alike = [[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    assert!(reason(p(&alike)).contains("convex"));
    refused(p(&[[0.0, 0.0], [f64::NAN, 0.0], [0.0, 1.0]]), "vertices");
    let huge = T::MAX.to_f64() / 2.0;
    refused(p(&[[-huge, -huge], [huge, -huge], [0.0, huge]]), "vertices");
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let bad = T::from_f64(bad);
        refused(Shape::circle(bad), "radius");
        refused(Shape::capsule(bad, T::one()), "half_length");
        refused(Shape::capsule(T::one(), bad), "radius");
        refused(Shape::rectangle(bad, T::one()), "width");
        refused(Shape::rectangle(T::one(), bad), "height");
    }
    refused(
        Shape::rectangle(T::one(), T::one())?.rounded(T::from_f64(-0.1)),
        "radius",
    );
    let rounded = Shape::rectangle(T::one(), T::one())?.rounded(T::from_f64(0.25))?;
    assert_eq!(
        (rounded.vertices().len(), rounded.radius()),
        (4, T::from_f64(0.25))
    );
    let (lo, hi) = rounded.bounds();
    assert_eq!((lo, hi), ([T::from_f64(-0.75); 2], [T::from_f64(0.75); 2]));
    Ok(())
}

/// A box resting flat on an equal one, 1 mm into it, tipped either way by up to a few
/// tenths of a milliradian (a column at rest, its boxes rocking by the rounding of their
/// impulses), names its two points by the same features whichever way it tips: the lower
/// box's top face stays the reference, so that a solver's impulses are matched from step
/// to step. (Each face was the reference by turns: the ids changed with the sign of the
/// tip, and a column of five boxes, warm-started every other step, crept 0.34 m in 20 s.)
fn resting_faces_keep_their_ids<T: Real>() -> Result<(), Error> {
    let unit = Shape::rectangle(T::one(), T::one())?;
    let lower = unit.placed(&pose(0.0, 0.0, 0.0));
    let ids = |angle: f64| {
        let m = collide(&lower, &unit.placed(&pose(0.002, 0.999, angle)), T::zero());
        let mut ids: Vec<u32> = m.points().iter().map(|p| p.id).collect();
        ids.sort_unstable();
        ids
    };
    let flat = ids(0.0);
    assert_eq!(flat.len(), 2, "{flat:?}");
    // The first shape's face is the reference: the ids' flag of the second's (bit 24) clear.
    assert!(flat.iter().all(|id| id >> 24 == 0), "{flat:x?}");
    for angle in [1e-7, -1e-7, 1e-5, -1e-5, 3e-4, -3e-4] {
        assert_eq!(ids(angle), flat, "tipped by {angle}");
    }
    Ok(())
}

for_f32_and_f64!(
    resting_faces_keep_their_ids,
    shapes_are_validated,
    circles,
    boxes,
    capsules,
    half_planes,
    random_pairs_touch_when_moved_by_their_gap
);
