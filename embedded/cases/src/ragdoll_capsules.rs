//! [`ragdoll_capsules`]: a capsule on each of a ragdoll's links, as the pile test, the world
//! bench and the page's sandbox put them (one definition, so that the three are one body).

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Real};
use lagrange_systems::{Ragdoll, RAGDOLL_LINKS};
use lagrange_world::Shape;

/// The capsule radius of each link, m: the torso 0.12, the head 0.1, every limb 0.05.
pub const RAGDOLL_CAPSULE_RADII: [f64; RAGDOLL_LINKS] =
    [0.12, 0.1, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05];

/// The capsule of each link of `doll` in the link's frame, as long as the link: the torso's
/// about its centre, a limb's from its joint along `-y`, radii [`RAGDOLL_CAPSULE_RADII`].
///
/// # Errors
/// [`Error::InvalidParameter`] where a link's length is not a capsule's (not finite).
pub fn ragdoll_capsules<T: Real>(doll: &Ragdoll<T>) -> Result<[Shape<T>; RAGDOLL_LINKS], Error> {
    let rest = doll.segments(&SVector::zeros());
    let mut out = [Shape::circle(T::one())?; RAGDOLL_LINKS];
    let links = rest.iter().zip(RAGDOLL_CAPSULE_RADII);
    for (k, (slot, ([a, b], radius))) in out.iter_mut().zip(links).enumerate() {
        // libm's hypot: the same bits on every target (a platform's own may differ).
        let length = libm::hypot((a[0] - b[0]).to_f64(), (a[1] - b[1]).to_f64());
        let centre = if k == 0 { 0.0 } else { -length / 2.0 };
        *slot = Shape::capsule(T::from_f64(length / 2.0), T::from_f64(radius))?.offset(
            [T::zero(), T::from_f64(centre)],
            T::from_f64(core::f64::consts::FRAC_PI_2),
        );
    }
    Ok(out)
}
