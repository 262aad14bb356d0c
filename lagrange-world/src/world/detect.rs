//! Step 2 of a [`World`]'s step: where its shapes touch or may touch in the step, as contact
//! rows in the bodies' coordinates; sleeping bodies an awake one touches are woken.

use super::bodies::Attached;
use super::limits::{Limits, MAX_OWN_ROWS};
use super::places::{self, Place};
use super::profile::{Profile, Stopwatch};
use super::rows::{Contact, Row};
use super::{World, OWN_ROWS};
use crate::broad::Proxy;
use crate::collide::{collide, half_plane_points};
use crate::sweep::{closing, swept, touches, Touch};
use crate::vec2::Vec2;
use heapless::Vec;
use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Mechanism, Real};

/// One side of a contact: a shape's key, the body and link it is on (none: static), and
/// its link's pose (not its whole place: a side is handed to every contact point of a
/// pair, and a placed polygon is hundreds of bytes to copy).
#[derive(Debug, Clone, Copy)]
struct Side<T> {
    key: u32,
    on: Option<(usize, usize)>,
    pose: Pose<T>,
}

impl<T, M, L, const N: usize, const B: usize, const S: usize, const K: usize>
    World<T, M, N, B, S, K, L>
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    /// The step's contacts, sorted by key, warm-started from the last step's impulses; the
    /// number of bodies woken. Each awake body's shapes are looked for as far as its velocity
    /// takes them in the step. A second look (`before`: the velocities before the first
    /// phase's impulses, by body) looks as far as either takes them, and starts from no
    /// impulses: the first's are in the velocities.
    pub(super) fn detect(
        &mut self,
        dt: T,
        before: Option<&[SVector<T, N>; B]>,
        watch: &mut Stopwatch,
        profile: &mut Profile,
    ) -> Result<u32, Error> {
        let mut woke = 0;
        loop {
            // A body woken has had no free step; its contacts are found again with it.
            let woken = self.find(dt, before, watch, profile)?;
            if woken == 0 {
                break;
            }
            woke += woken;
        }
        self.contacts.sort_unstable_by_key(|c| c.key);
        if before.is_some() {
            profile.narrow += watch.lap();
            return Ok(woke);
        }
        // Both sorted by key: matched in one walk (a binary search a contact was most of the
        // matching).
        let mut kept = self.kept.iter().peekable();
        for c in self.contacts.iter_mut() {
            while kept.next_if(|k| k.key < c.key).is_some() {}
            if let Some(k) = kept.next_if(|k| k.key == c.key) {
                c.normal.lambda = k.normal;
                c.tangent.lambda = k.tangent;
            }
        }
        profile.narrow += watch.lap();
        Ok(woke)
    }

    /// One pass of detection; the number of sleeping bodies it woke (their contacts are then
    /// incomplete: the caller finds them again).
    fn find(
        &mut self,
        dt: T,
        before: Option<&[SVector<T, N>; B]>,
        watch: &mut Stopwatch,
        profile: &mut Profile,
    ) -> Result<u32, Error> {
        self.contacts.clear();
        self.broad.clear();
        // Every pair and every half-plane needs a body awake: a world asleep finds nothing
        // (and costs nothing here).
        if self.bodies.iter().all(|b| b.asleep) {
            profile.broad += watch.lap();
            return Ok(0);
        }
        places::place(
            &mut self.places,
            &self.shapes,
            &self.by_body,
            &self.bodies,
            dt,
            before,
        );
        let margin = self.settings.margin;
        for (index, (s, place)) in self.shapes.iter().zip(&self.places).enumerate() {
            let (lo, hi) = place.shape.bounds();
            let grow = margin + place.reach;
            let body = s.on.map(|(i, _)| i);
            // Each proxy known by its shape's place: unique, and in the order of the shapes'
            // keys (the shapes are sorted by key), so the pairs come in the keys' order, and
            // a pair's shapes are found without a search.
            self.broad
                .add_unique(Proxy {
                    bounds: ([lo[0] - grow, lo[1] - grow], [hi[0] + grow, hi[1] + grow]),
                    body: body.map_or(u32::MAX, |i| u32::try_from(i).unwrap_or(u32::MAX)),
                    key: u32::try_from(index).unwrap_or(u32::MAX),
                    group: s.group,
                    mask: s.mask,
                    fixed: body.is_none(),
                    asleep: body.is_some_and(|i| self.bodies.get(i).is_some_and(|b| b.asleep)),
                })
                // A box that is not finite: a body so far out that its shape's place overflows.
                .map_err(|_| Error::NonFiniteState)?;
        }
        let mut pairs: Vec<(u32, u32), K> = Vec::new();
        self.broad.pairs(&mut pairs)?;
        profile.broad += watch.lap();
        let mut woken = 0;
        for &(ia, ib) in &pairs {
            let (ia, ib) = (ia as usize, ib as usize);
            let (Some(pa), Some(pb)) = (self.places.get(ia), self.places.get(ib)) else {
                continue;
            };
            let (Some(sa), Some(sb)) = (self.shapes.get(ia), self.shapes.get(ib)) else {
                continue;
            };
            let cover = margin + pa.reach + pb.reach;
            let met = fast_pair((sa, pa), (sb, pb), margin, cover);
            let (normal, touches) = met.unwrap_or_else(|| {
                let m = collide(&pa.shape, &pb.shape, cover);
                (m.normal, touches(&m))
            });
            if touches.is_empty() {
                continue;
            }
            let (Some(a), Some(b)) = (self.side(ia), self.side(ib)) else {
                continue;
            };
            let sleeper = [a, b]
                .iter()
                .filter_map(|s| s.on)
                .find(|&(i, _)| self.bodies.get(i).is_some_and(|b| b.asleep));
            if let Some((i, _)) = sleeper {
                woken += self.wake_island(i, dt)?;
                continue;
            }
            for p in &touches {
                self.push(a, b, normal, p, dt)?;
            }
        }
        for pi in 0..self.planes.len() {
            let Some(&(key, plane)) = self.planes.get(pi) else {
                continue;
            };
            for si in 0..self.shapes.len() {
                let awake = self
                    .shapes
                    .get(si)
                    .and_then(|s| s.on)
                    .is_some_and(|(i, _)| self.bodies.get(i).is_some_and(|b| !b.asleep));
                let (Some(place), Some(s)) = (self.places.get(si), self.side(si)) else {
                    continue;
                };
                if !awake {
                    continue;
                }
                // Every vertex that may touch in the step (see `half_plane_points`).
                let points = half_plane_points(&plane, &place.shape, margin + place.reach);
                // A half-plane has no shape to place; a static side's pose is never read.
                let wall = Side {
                    key,
                    on: None,
                    pose: s.pose,
                };
                for p in &points {
                    self.push(wall, s, plane.normal(), &Touch::from(p), dt)?;
                }
            }
        }
        self.mobilities()?;
        for i in 0..self.bodies.len() {
            self.own_rows(i, dt)?;
        }
        profile.narrow += watch.lap();
        Ok(woken)
    }

    /// Shape `index` as a side of a contact.
    fn side(&self, index: usize) -> Option<Side<T>> {
        let (s, place) = (self.shapes.get(index)?, self.places.get(index)?);
        Some(Side {
            key: s.key,
            on: s.on,
            pose: place.pose,
        })
    }

    /// The rows of awake body `i`'s own (its limits), as contacts with nothing on their
    /// other side (no friction), their mobilities from one call of the mass solve.
    fn own_rows(&mut self, i: usize, dt: T) -> Result<(), Error> {
        let Some(body) = self.bodies.get(i).filter(|b| !b.asleep) else {
            return Ok(());
        };
        let mut rows: Vec<(u32, T), MAX_OWN_ROWS> = Vec::new();
        let mut jacobians = SMatrix::<T, N, MAX_OWN_ROWS>::zeros();
        let mut full = false;
        body.limits.rows(&body.state.q, |row, gap, j| {
            let k = rows.len();
            full |= rows.push((row, gap)).is_err();
            if k < MAX_OWN_ROWS {
                jacobians.set_column(k, &j);
            }
        });
        if full {
            return Err(Error::InvalidParameter {
                name: "limits",
                reason: "a body has more own rows than MAX_OWN_ROWS",
            });
        }
        let mut mobilities = jacobians;
        body.mechanism
            .velocity_jumps(&body.state, &mut mobilities)?;
        let zero = SVector::<T, N>::zeros();
        let key = body.key;
        for (k, &(row, gap)) in rows.iter().enumerate() {
            let (j, b) = (
                jacobians.column(k).into_owned(),
                mobilities.column(k).into_owned(),
            );
            let approach = j.dot(&body.state.qd);
            let lower = self.lowest(gap, approach, dt);
            // Straight into the world's contacts (a contact is some 800 bytes in f64; made
            // in a list of the body's first, each was copied twice: a tenth of a pile's
            // step went to copies here and in the pairs' rows).
            self.contacts
                .push(Contact {
                    key: (OWN_ROWS, key, row),
                    bodies: [Some(i), None],
                    normal: Row::new([j, zero], [b, zero]),
                    tangent: Row::new([zero; 2], [zero; 2]),
                    gap,
                    lower,
                    approach,
                    drift: T::zero(),
                    reach: T::zero(),
                    point: [T::zero(); 2],
                    direction: [T::zero(); 2],
                    twin: None,
                })
                .map_err(|_| capacity())?;
        }
        Ok(())
    }

    /// The lowest speed of a row of gap `gap` closing at `-approach` (see `Contact::lower`).
    fn lowest(&self, gap: T, approach: T, dt: T) -> T {
        let model = self.settings.model;
        // Open: it may close in the step, no more; touching: it may not close further.
        let lower = if gap > T::zero() {
            -gap / dt
        } else {
            T::zero()
        };
        // Striking (closing in the step, and fast enough to leave at the rest speed or
        // more): Newton's rebound. Slower, it rests: a body on the floor gains g dt a step,
        // which must not bounce it.
        let rebound = -model.restitution() * approach;
        if rebound >= model.rest_speed() && gap + approach * dt <= T::zero() {
            lower.max(rebound)
        } else {
            lower
        }
    }

    /// Wakes the island body `i` fell asleep with, each body with its free step: how many.
    fn wake_island(&mut self, i: usize, dt: T) -> Result<u32, Error> {
        let Some(island) = self.bodies.get(i).map(|b| b.island) else {
            return Ok(0);
        };
        let mut n = 0;
        for body in self
            .bodies
            .iter_mut()
            .filter(|b| b.asleep && b.island == island)
        {
            body.wake();
            body.free(dt)?;
            n += 1;
        }
        Ok(n)
    }

    /// The contact at `p` between `a` and `b` (normal `n` from `a` to `b`): its rows at the
    /// bodies' coordinates, and its lowest speed.
    fn push(
        &mut self,
        a: Side<T>,
        b: Side<T>,
        n: Vec2<T>,
        p: &Touch<T>,
        dt: T,
    ) -> Result<(), Error> {
        let t = [-n[1], n[0]];
        let zero = SVector::<T, N>::zeros();
        let (mut jn, mut jt) = ([zero; 2], [zero; 2]);
        let mut approach = T::zero();
        let sides = [(a, -T::one()), (b, T::one())].into_iter().zip(p.ends);
        for (s, ((side, sign), end)) in sides.enumerate() {
            let Some((body, link)) = side.on.and_then(|(i, l)| Some((self.bodies.get(i)?, l)))
            else {
                continue;
            };
            let j = body
                .mechanism
                .jacobian_at(&body.state.q, link, &side.pose, end);
            let along = |d: Vec2<T>| {
                SVector::<T, N>::from_fn(|k, _| sign * (d[0] * j[(0, k)] + d[1] * j[(1, k)]))
            };
            let (normal, tangent) = (along(n), along(t));
            approach += normal.dot(&body.state.qd);
            if let (Some(x), Some(y)) = (jn.get_mut(s), jt.get_mut(s)) {
                (*x, *y) = (normal, tangent);
            }
        }
        let gap = p.gap;
        let lower = self.lowest(gap, approach, dt);
        self.contacts
            .push(Contact {
                key: (a.key, b.key, p.id),
                bodies: [a.on.map(|(i, _)| i), b.on.map(|(i, _)| i)],
                // Their mobilities come with the others' of the same bodies (`mobilities`).
                normal: Row::unsolved(jn),
                tangent: Row::unsolved(jt),
                gap,
                lower,
                approach,
                drift: T::zero(),
                reach: T::zero(),
                point: p.at,
                direction: n,
                twin: None,
            })
            .map_err(|_| capacity())
    }
}

/// The contact of a pair closing in the step farther than the thinner of them is half
/// thick, at the features where they first meet (see `sweep`), its points within `cover`;
/// `None` where the features closest now are the contact's.
fn fast_pair<T: Real>(
    (sa, pa): (&Attached<T>, &Place<T>),
    (sb, pb): (&Attached<T>, &Place<T>),
    margin: T,
    cover: T,
) -> Option<(Vec2<T>, Vec<Touch<T>, 2>)> {
    let thinner = sa.half_width.min(sb.half_width);
    // Their reaches bound their closing: a pile at rest looks no further.
    if pa.reach + pb.reach <= thinner {
        return None;
    }
    let (a, b) = (pa.moving(sa), pb.moving(sb));
    if closing(&a, &b) <= thinner {
        return None;
    }
    swept(&a, &b, margin, cover)
}

/// More contact points than the world holds.
fn capacity() -> Error {
    Error::InvalidParameter {
        name: "capacity",
        reason: "more contact points than K",
    }
}
