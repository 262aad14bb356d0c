//! The page's code on the host: every panel steps and draws finite points in both
//! precisions, bad input is refused with the library's error and resets the instance, and the
//! scenario's words are the lockstep case's.

use lagrange_cases::{scripted, world_in_a_box, STEPS};
use lagrange_web::page::Page;
use lagrange_web::scenario;
use lagrange_web::setups::{make, twin_angle, KINDS, METHODS};

/// Every panel in both precisions and every integrator: a third of a second of frames, finite points,
/// a small energy error for the conservative ones.
#[test]
fn every_panel_steps_and_draws_finite_points() -> Result<(), lagrange_core::Error> {
    for kind in 0..KINDS.len() {
        for method in 0..METHODS.len() {
            for double in [false, true] {
                let mut panel = if double {
                    make::<f64>(kind, method)?
                } else {
                    make::<f32>(kind, method)?
                };
                for _ in 0..20 {
                    panel.advance(1.0 / 60.0);
                }
                assert!(panel.take_error().is_none(), "{kind} {method} {double}");
                let mut points = Vec::new();
                let counts = panel.points(&mut points);
                assert!(counts.main >= 2);
                assert!(points.iter().all(|x| x.is_finite()));
                assert!((panel.time() - 1.0 / 3.0).abs() < 0.02, "{}", panel.time());
                // Contacts dissipate (the floor and the ragdoll); the rest conserve.
                if kind < 5 {
                    let e = panel.energy_error().abs();
                    assert!(e < 0.05, "kind {kind} method {method}: {e}");
                }
            }
        }
    }
    Ok(())
}

/// A dt of 0 or NaN is refused with the library's error and the panel reset to its start
/// and default step; an absurd throw is refused or fails the step, and the panel is reset.
#[test]
fn bad_input_is_refused_and_resets() -> Result<(), lagrange_core::Error> {
    let mut page = Page::default();
    page.init(true)?;
    for bad in [0.0, f64::NAN, -1.0, f64::INFINITY] {
        let panel = &mut page.panels[0];
        panel.advance(0.1);
        assert!(panel.set_dt(bad).is_err());
        assert!(panel.take_error().is_some());
        assert_eq!(panel.time(), 0.0);
        assert_eq!(panel.dt(), 1.0 / 60.0);
    }
    let ragdoll = &mut page.panels[6];
    let refused = ragdoll.drag(3, 1e300, -1e300).is_err();
    ragdoll.advance(0.1);
    assert!(refused || ragdoll.take_error().is_some());
    let mut points = Vec::new();
    ragdoll.points(&mut points);
    assert!(points.iter().all(|x| x.is_finite()));
    assert!(ragdoll.energy_error().is_finite());
    // A drag at a sane speed wakes the instance and moves it.
    let pendulum = &mut page.panels[0];
    pendulum.drag(1, 2.0, 0.0)?;
    assert_eq!(pendulum.status(), 0);
    Ok(())
}

/// The page's scenarios are the lockstep cases the firmware runs (the scene's, the world's), and
/// their digests are of their words.
#[test]
fn scenario_is_the_lockstep_case() -> Result<(), lagrange_core::Error> {
    let words = scenario::words(false)?;
    assert_eq!(words, scripted::<f32>(STEPS)?.words());
    let text = scenario::text(true);
    let digest = scenario::digest(&scenario::words(true)?);
    assert!(text.ends_with(&format!("digest={digest:016x}")), "{text}");
    let world = scenario::world_words()?;
    assert_eq!(world, world_in_a_box(STEPS)?.words());
    let text = scenario::world_text();
    assert!(text.starts_with("world frames="), "{text}");
    let digest = scenario::digest(&world);
    assert!(text.ends_with(&format!("digest={digest:016x}")), "{text}");
    Ok(())
}

/// The chaotic twin starts 1e-9 rad away in `f64`, one `f32` away in `f32`: never on top.
#[test]
fn the_twin_is_apart() {
    assert!((twin_angle(2.2_f64) - 2.2 - 1e-9).abs() < 1e-15);
    let twin = twin_angle(2.2_f32);
    assert!(twin > 2.2_f32);
    assert_eq!(twin, f32::from_bits(2.2_f32.to_bits() + 1));
}
