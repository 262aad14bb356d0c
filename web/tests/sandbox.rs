//! The page's sandbox on the host: the scripted pile is the same bits run twice and in each
//! precision it runs in, its shapes are finite and drawable, a grab finds the body under the
//! pointer, a throw moves it, and no step comes near the contact cap.

use lagrange_core::Error;
use lagrange_web::sandbox::{script_step, scripted, Sandbox, CONTACT_CAP, SCRIPT_STEPS};

/// The scripted run gives the same digest each time in `f64`.
#[test]
fn the_scripted_pile_is_deterministic_in_f64() -> Result<(), Error> {
    assert_eq!(
        scripted::<f64>(SCRIPT_STEPS)?,
        scripted::<f64>(SCRIPT_STEPS)?
    );
    Ok(())
}

/// The scripted run gives the same digest each time in `f32`, and its own: not the `f64`
/// run's (compared over the script's first tenth, where the two precisions' bits already
/// part; the whole script in both is the test above's and this one's work again).
#[test]
fn the_scripted_pile_is_deterministic_in_f32() -> Result<(), Error> {
    assert_eq!(
        scripted::<f32>(SCRIPT_STEPS)?,
        scripted::<f32>(SCRIPT_STEPS)?
    );
    let part = SCRIPT_STEPS / 10;
    assert_ne!(scripted::<f64>(part)?, scripted::<f32>(part)?);
    Ok(())
}

/// Through the scripted run: every shape finite at every step (a circle one vertex, a capsule
/// two, a box four), the most contact points of any step well below the cap, and by its
/// end most bodies asleep (the thrown ragdoll and box come to rest within the 6 s left).
#[test]
fn the_pile_is_drawable_and_settles() -> Result<(), Error> {
    let mut sandbox = Sandbox::<f64>::new()?;
    let mut out = Vec::new();
    for i in 0..SCRIPT_STEPS {
        script_step(&mut sandbox, i)?;
        out.clear();
        let shapes = sandbox.shapes(&mut out);
        assert_eq!(shapes, 10 + 6 + 2 + 4 + 2 * 10, "step {i}");
        assert!(out.iter().all(|x| x.is_finite()), "step {i}");
        let mut at = 0;
        for _ in 0..shapes {
            let vertices = out[at + 2] as usize;
            assert!([1, 2, 4].contains(&vertices), "step {i}: {vertices}");
            at += 3 + 2 * vertices;
        }
        assert_eq!(at, out.len());
    }
    let [bodies, awake, _, worst, cap] = sandbox.info();
    assert_eq!((bodies, cap as usize), (21, CONTACT_CAP));
    assert!(worst > 0 && (worst as usize) < CONTACT_CAP / 2, "{worst}");
    assert!(awake < bodies / 2, "{awake} of {bodies} awake");
    Ok(())
}

/// A grab at the pyramid's top box finds that box; thrown upward at 5 m/s, it rises by a step
/// of that speed less gravity's (8.1 cm, to the rounding of the contacts below it, which no
/// longer push); a grab in the air finds nothing; a throw of no body, or at a speed that is
/// not finite, is refused.
#[test]
fn grab_and_throw() -> Result<(), Error> {
    let mut sandbox = Sandbox::<f64>::new()?;
    assert_eq!(sandbox.grab(-3.2, 0.25), Some(0));
    let top = sandbox.grab(-2.375, 1.75);
    assert_eq!(top, Some(9));
    assert_eq!(sandbox.grab(0.0, 7.5), None);
    sandbox.throw(9, 0.0, 5.0)?;
    sandbox.step()?;
    let mut out = Vec::new();
    sandbox.shapes(&mut out);
    // Shapes in their keys' order: the top box's (the tenth, each box 3 + 8 numbers).
    let corners: Vec<f64> = (0..4).map(|k| out[99 + 3 + 2 * k + 1]).collect();
    let lowest = corners.iter().copied().fold(f64::INFINITY, f64::min);
    let rise = 5.0 / 60.0 - 9.81 / 3600.0;
    assert!((lowest - (1.5 + rise)).abs() < 1e-3, "{corners:?}");
    assert!(matches!(
        sandbox.throw(99, 1.0, 1.0),
        Err(Error::InvalidParameter { name: "body", .. })
    ));
    assert!(sandbox.throw(0, f64::NAN, 1.0).is_err());
    Ok(())
}
