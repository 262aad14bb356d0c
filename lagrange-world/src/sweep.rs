//! Where two shapes moving through a step first come close: conservative advancement.
//!
//! A contact taken where two shapes are closest at a step's start is the wrong contact when
//! they close on each other farther in the step than the thinner of them is half thick: a ball 5 m from a
//! plank 1 cm thick, coming at it slantwise at 300 m/s, is closest to the plank's end at
//! the start, and it strikes the plank's middle. Its speculative contact at the end either
//! stops it where there is nothing (a ghost impulse) or lets it through the middle: a ball
//! of 10 cm radius shot at 20 to 1,000 m/s at a free plank of 0.1 to 100 kg, bouncing,
//! passed through or sank past the slop in 36 of 768 shots (`tests/tests/world_fast.rs`).
//! Moved to where they first come within the margin, the two shapes meet at the features
//! that will touch: none of the 768 fails. Where they do not meet in the step, the advance
//! ends where they come closest, and a speculative contact there guards a path the impulses
//! bend; taken at the start's closest features instead, a ball stopping 5 cm short of a
//! light plank's middle struck the plank's end (closest at the start, 1.3 m off its path) a
//! ghost blow that spun it at 159 rad/s.
//!
//! Each shape's link moves from its pose at the step's start to its pose at the step's end
//! (its coordinates advanced by its velocities), origin and angle in proportion to the
//! time: no point of one moves from a point of the other farther than their closing a step
//! (their origins' move from each other, and each one's turn times its extent), so the two
//! come no closer than their separation less their closing times the time, and a step in
//! time of (separation - half the margin) / closing never takes them into each other
//! (Mirtich's conservative advancement). Only a pair whose closing is more than the thinner
//! is half thick is advanced: the rest take their contact at the start, as before (a pile
//! falling together closes little, however fast it falls). A few such steps
//! meet a head-on strike; a grazing one takes more, and after [`ADVANCES`] the advance ends
//! where it is, short of the meeting (never past it).
//!
//! The contact is then taken there, each of its points carried back to the step's start on
//! each shape: a body is pushed at the start at the point of it that will touch, and the
//! gap now is the gap there plus the two points' moves along the normal.
//!
//! What one contact a step cannot do: follow a ball that strikes a free plank with no bounce
//! and then slides along it farther in a step than the plank is long while it spins (the
//! plank's face turns under the ball's new place, a second-order move the rows taken at the
//! start do not see). Over the same shots at restitution 0, 109 of 576 end deeper than the
//! slop and 25 on the far side (217 and 108 with the contacts at the start's features); on a
//! static plank, 1 of 192 (a graze of its end at 1,000 m/s that slips round the corner
//! onto its face).

use crate::collide::{collide, core_distance};
use crate::manifold::{ContactPoint, Manifold};
use crate::shape::Shape;
use crate::vec2::{add, dot, length, rotate, sub, Vec2};
use heapless::Vec;
use lagrange_core::links::Pose;
use lagrange_core::Real;

/// The most steps of an advance (a strike head-on takes two or three, a graze more: each
/// closes a share of the gap).
const ADVANCES: usize = 24;

/// Half the thinnest width of `shape`: its radius and, for a polygon, half the least depth
/// of its core behind any of its edges (a box's half height where it is wider than high). A
/// shape closing on it farther than this in a step may pass the features closest at the
/// step's start.
pub(crate) fn half_width<T: Real>(shape: &Shape<T>) -> T {
    let (vertices, normals) = (shape.vertices(), shape.normals());
    let depth = |(&w, &n): (&Vec2<T>, &Vec2<T>)| {
        vertices
            .iter()
            .map(|&v| -dot(sub(v, w), n))
            .fold(T::zero(), T::max)
    };
    // A point or a segment has no depth behind an edge.
    let least = if vertices.len() >= 3 {
        vertices
            .iter()
            .zip(normals)
            .map(depth)
            .fold(T::INFINITY, T::min)
    } else {
        T::zero()
    };
    shape.radius() + least * T::HALF
}

/// How far apart the surfaces of `a` and `b` are (negative: overlapping by up to their
/// radii), or `None` where their cores overlap.
fn separation<T: Real>(a: &Shape<T>, b: &Shape<T>) -> Option<T> {
    core_distance(a, b).map(|(_, _, d)| d - (a.radius() + b.radius()))
}

/// A shape moving through a step: its shape in its link's frame, its link's pose at the
/// step's start and at its end, and how far its farthest point is from its link's origin.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Moving<'a, T> {
    pub(crate) shape: &'a Shape<T>,
    pub(crate) from: Pose<T>,
    pub(crate) to: Pose<T>,
    pub(crate) extent: T,
}

/// How far any point of `b` moves from any point of `a` in the step, at most: their links'
/// origins' move from each other, and each one's turn times its extent (two bodies falling
/// side by side close nothing, however fast they fall).
pub(crate) fn closing<T: Real>(a: &Moving<'_, T>, b: &Moving<'_, T>) -> T {
    let moved = |m: &Moving<'_, T>| sub(m.to.origin, m.from.origin);
    let turned = |m: &Moving<'_, T>| (m.to.angle - m.from.angle).abs() * m.extent;
    length(sub(moved(b), moved(a))) + turned(a) + turned(b)
}

impl<T: Real> Moving<'_, T> {
    /// Its link's pose at `t` of the step (0 its start, 1 its end).
    pub(crate) fn pose(&self, t: T) -> Pose<T> {
        let (a, b) = (self.from, self.to);
        let along = |x: T, y: T| x + (y - x) * t;
        Pose {
            origin: [
                along(a.origin[0], b.origin[0]),
                along(a.origin[1], b.origin[1]),
            ],
            angle: along(a.angle, b.angle),
        }
    }

    /// Its shape placed at `t` of the step.
    pub(crate) fn at(&self, t: T) -> Shape<T> {
        self.shape.placed(&self.pose(t))
    }

    /// Where the point of it at `p` at `t` of the step is at the step's start.
    fn back(&self, t: T, p: Vec2<T>) -> Vec2<T> {
        let then = self.pose(t);
        let (s, c) = then.angle.sin_cos();
        let local = rotate(sub(p, then.origin), (-s, c));
        let (s, c) = self.from.angle.sin_cos();
        add(self.from.origin, rotate(local, (s, c)))
    }
}

/// A contact point of two moving shapes: where it is on each at the step's start (the first
/// shape's point, the second's), where they touch (midway between their surfaces when they
/// come closest), the gap between them now along the normal, and the features that meet.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Touch<T> {
    pub(crate) ends: [Vec2<T>; 2],
    pub(crate) at: Vec2<T>,
    pub(crate) gap: T,
    pub(crate) id: u32,
}

impl<T: Real> From<&ContactPoint<T>> for Touch<T> {
    /// A point of a manifold taken at the step's start: one point on both shapes.
    fn from(p: &ContactPoint<T>) -> Self {
        Self {
            ends: [p.point; 2],
            at: p.point,
            gap: p.gap,
            id: p.id,
        }
    }
}

/// The points of a manifold taken at the step's start, as touches.
pub(crate) fn touches<T: Real>(m: &Manifold<T>) -> Vec<Touch<T>, 2> {
    let mut touches = Vec::new();
    for p in m.points() {
        // (A manifold has at most two points.)
        let _ = touches.push(Touch::from(p));
    }
    touches
}

/// Where `a` and `b` touch when they first come within `margin` of each other in the step
/// (or where they come closest, if they do not), carried back to the step's start: the
/// normal (from `a` to `b`) and the points within `cover` there (as far apart as the
/// impulses could still take them, the margin the contact at the start is looked for
/// with), each on both shapes where it will be, with the gap between them now. `None` where
/// they are within `margin` at the start, or come no closer in the step (the manifold at the
/// start is the contact).
pub(crate) fn swept<T: Real>(
    a: &Moving<'_, T>,
    b: &Moving<'_, T>,
    margin: T,
    cover: T,
) -> Option<(Vec2<T>, Vec<Touch<T>, 2>)> {
    let t = first_meeting(a, b, margin);
    if t <= T::zero() {
        return None;
    }
    let m = collide(&a.at(t), &b.at(t), cover);
    let n = m.normal;
    let mut touches = Vec::new();
    for p in m.points() {
        let ends = [a.back(t, p.point), b.back(t, p.point)];
        // (A manifold has at most two points.)
        let _ = touches.push(Touch {
            ends,
            at: p.point,
            // Each end moves with its shape from here to `p`.
            gap: p.gap + dot(n, sub(ends[1], ends[0])),
            id: p.id,
        });
    }
    Some((n, touches))
}

/// How far into the step (0 to 1) the advance of `a` and `b` goes: to the time they first
/// come within `margin` (> 0) of each other (or a time before that where the advance took
/// all its steps), or, where they stay farther apart through the step, to the last time it
/// reached, past which they cannot come within the margin before the step's end: on a path
/// that closes, near where they come closest (the features a speculative contact of theirs
/// is to be taken at: those closest at the start may be ones they never come near, and a
/// contact there pushes them apart for nothing).
pub(crate) fn first_meeting<T: Real>(a: &Moving<'_, T>, b: &Moving<'_, T>, margin: T) -> T {
    let speed = closing(a, b);
    let mut t = T::zero();
    for _ in 0..ADVANCES {
        // Cores that overlap are touching.
        let Some(d) = separation(&a.at(t), &b.at(t)) else {
            return t;
        };
        if d <= margin {
            return t;
        }
        // (Compared so that a speed of zero or NaN ends it: the shapes do not meet.)
        let step = (d - margin * T::HALF) / speed;
        if !(step.is_finite() && t + step <= T::one()) {
            return t;
        }
        t += step;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(x: f64, y: f64) -> Pose<f64> {
        Pose {
            origin: [x, y],
            angle: 0.0,
        }
    }

    /// A bar 4 m long and 1 cm thick turning about its middle from -0.04 to 0.06 rad in the
    /// step (its tips 0.2 m), and a ball of radius 0.1 at rest 1.5 m out, 0.1 rad round:
    /// the bar's face reaches the ball when the bar is at 0.03 rad, 0.7 of the step in. The
    /// advance, bounded by the bar's turn times its reach, meets it there within the margin
    /// and never inside it, in the few steps a turn this slow needs.
    #[test]
    fn a_turning_bar_meets_a_ball_where_its_face_sweeps_it() -> Result<(), lagrange_core::Error> {
        let bar = Shape::rectangle(4.0, 0.01)?;
        let ball = Shape::circle(0.1)?;
        let margin = 0.004;
        let turning = |angle: f64| Pose {
            origin: [0.0, 0.0],
            angle,
        };
        let a = Moving {
            shape: &bar,
            from: turning(-0.04),
            to: turning(0.06),
            extent: (2.0_f64.powi(2) + 0.005_f64.powi(2)).sqrt(),
        };
        let (s, c) = 0.1_f64.sin_cos();
        let b = Moving {
            shape: &ball,
            from: still(1.5 * c, 1.5 * s),
            to: still(1.5 * c, 1.5 * s),
            extent: 0.1,
        };
        let t = first_meeting(&a, &b, margin);
        let d = separation(&a.at(t), &ball.placed(&b.from)).unwrap_or(-1.0);
        assert!((margin / 2.0..=margin).contains(&d), "{d} m apart at {t}");
        // Where the face reaches the ball: sin(0.1 - angle) = 0.105 / 1.5.
        let meets = (0.1 - (0.105_f64 / 1.5).asin() + 0.04) / 0.1;
        assert!(
            t < meets && t > meets - 0.05,
            "at {t}, not just before {meets}"
        );
        Ok(())
    }

    /// Half the thinnest width of each kind of shape, worked by hand: a plank's half
    /// thickness whichever way it stands, a circle's and a capsule's radius, a rounded box's
    /// half height and rounding, an equilateral triangle's half height (sqrt 3 / 4 for sides
    /// of 1), whichever vertex it is given from.
    #[test]
    fn half_widths() -> Result<(), lagrange_core::Error> {
        let h = 3.0_f64.sqrt() / 2.0;
        let cases = [
            (Shape::rectangle(4.0, 0.01)?, 0.005),
            (Shape::rectangle(0.01, 4.0)?, 0.005),
            (Shape::circle(0.1)?, 0.1),
            (Shape::capsule(0.5, 0.05)?, 0.05),
            (Shape::rectangle(1.0, 0.5)?.rounded(0.02)?, 0.27),
            (
                Shape::polygon(&[[0.0, 0.0], [1.0, 0.0], [0.5, h]])?,
                h / 2.0,
            ),
            (
                Shape::polygon(&[[1.0, 0.0], [0.5, h], [0.0, 0.0]])?,
                h / 2.0,
            ),
        ];
        for (shape, expected) in cases {
            let got = half_width(&shape);
            // Rounding of a few products of unit size.
            assert!(
                (got - expected).abs() < 1e-15,
                "{shape:?}: {got}, not {expected}"
            );
        }
        Ok(())
    }

    /// A ball of radius 0.1 coming down slantwise at a plank 4 m long and 1 cm thick (static),
    /// 5 m in the step: where its path crosses the plank, it meets it there, within the
    /// margin and never inside it; where it stops 5 cm short of it, or passes its end, it
    /// does not meet it, and the advance ends where it came closest (over the plank's
    /// middle, not at the end that was closest at the start).
    #[test]
    fn a_slanting_ball_meets_a_plank_where_its_path_crosses() -> Result<(), lagrange_core::Error> {
        let plank = Shape::rectangle(4.0, 0.01)?;
        let ball = Shape::circle(0.1)?;
        let margin = 0.02;
        let (s, c) = 0.5_f64.sin_cos();
        for (aim, past, meets) in [
            (0.0, 0.2, true),
            (1.5, 0.2, true),
            (-1.9, 0.2, true),
            (0.0, -0.05, false),
            (2.3, 0.2, false),
        ] {
            // `past` along the path beyond where the ball's centre would touch the face.
            let touch = [aim - 0.105 * s / c, 0.105];
            let end = [touch[0] + past * s, touch[1] - past * c];
            let from = [end[0] - 5.0 * s, end[1] + 5.0 * c];
            let a = Moving {
                shape: &plank,
                from: still(0.0, 0.0),
                to: still(0.0, 0.0),
                extent: 2.0,
            };
            let b = Moving {
                shape: &ball,
                from: still(from[0], from[1]),
                to: still(end[0], end[1]),
                extent: 0.1,
            };
            let t = first_meeting(&a, &b, margin);
            let d = separation(&plank, &b.at(t)).unwrap_or(-1.0);
            let centre = b.pose(t).origin;
            if meets {
                assert!(
                    (margin / 2.0..=margin).contains(&d),
                    "aimed at {aim}: {d} m apart at {t}"
                );
                assert!(
                    (centre[0] - aim).abs() < 0.1,
                    "aimed at {aim}: at {centre:?}"
                );
            } else {
                assert!(
                    d > margin,
                    "aimed at {aim}, {past} past: {d} m apart at {t}"
                );
                // Within 10 cm of the path's end (its last advance is half its gap back).
                assert!(
                    (centre[0] - end[0]).abs() < 0.1,
                    "aimed at {aim}, {past} past: at {centre:?}, {t}"
                );
            }
        }
        Ok(())
    }
}
