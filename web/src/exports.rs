//! The functions the page calls: plain C ABI, numbers in and out.
//!
//! Conventions: `panel` indexes `setups::KINDS`; a `u32` result of 0 means success and 1 an
//! error whose text [`lg_take_error`] gives; arrays come back through [`lg_numbers`] (an
//! address in the module's memory, `f64`s) and [`lg_text`] (UTF-8 bytes).

// `#[no_mangle]` is what makes a function an export of the .wasm; rustc counts it as unsafe
// code, because two exports of one name would clash at link time. The names below all
// start with `lg_` and are unique in this crate. No `unsafe` block is needed or used.
#![allow(unsafe_code)]

use std::cell::RefCell;

use lagrange_core::Error;

use crate::page::Page;
use crate::sandbox::{AnySandbox, SCRIPT_STEPS};
use crate::scenario;
use crate::setups::KINDS;
use crate::sim::Panel;

thread_local! {
    /// The page: WebAssembly runs it on one thread.
    static PAGE: RefCell<Page> = RefCell::new(Page::default());
}

/// Runs `f` on panel `panel`, or returns `missing`.
fn with_panel<R>(panel: u32, missing: R, f: impl FnOnce(&mut dyn Panel) -> R) -> R {
    PAGE.with_borrow_mut(|page| match page.panels.get_mut(panel as usize) {
        Some(p) => f(p.as_mut()),
        None => missing,
    })
}

/// 0 for `Ok`, 1 for an error (kept by the panel, or in the page's text).
fn code(result: Result<(), Error>) -> u32 {
    u32::from(result.is_err())
}

/// Builds every panel in `f64` (`double` = 1) or `f32` (0): the number of panels, or 0 when
/// one fails to build (its error in [`lg_text`]).
#[no_mangle]
pub extern "C" fn lg_init(double: u32) -> u32 {
    PAGE.with_borrow_mut(|page| match page.init(double != 0) {
        Ok(()) => u32::try_from(page.panels.len()).unwrap_or(0),
        Err(e) => {
            page.text = e.to_string();
            0
        }
    })
}

/// Number of mechanisms the page shows.
#[no_mangle]
pub extern "C" fn lg_panels() -> u32 {
    u32::try_from(KINDS.len()).unwrap_or(0)
}

/// Advances panel `panel` by `frame_time` s; its status after (0 awake, 1 asleep, 2 set
/// aside; a failed instance is reset at once and its error kept).
#[no_mangle]
pub extern "C" fn lg_advance(panel: u32, frame_time: f64) -> u32 {
    with_panel(panel, 2, |p| {
        p.advance(frame_time);
        p.status()
    })
}

/// Writes panel `panel`'s points to [`lg_numbers`]: `[main, twin, exact, x0, y0, x1, ...]`
/// (the three counts, then that many points of each group); the count of numbers.
#[no_mangle]
pub extern "C" fn lg_points(panel: u32) -> u32 {
    PAGE.with_borrow_mut(|page| {
        let Page {
            panels, numbers, ..
        } = page;
        numbers.clear();
        numbers.extend([0.0; 3]);
        let Some(p) = panels.get(panel as usize) else {
            return 3;
        };
        let counts = p.points(numbers);
        for (slot, n) in numbers
            .iter_mut()
            .zip([counts.main, counts.twin, counts.exact])
        {
            *slot = n as f64;
        }
        u32::try_from(numbers.len()).unwrap_or(0)
    })
}

/// The address of the numbers [`lg_points`] wrote.
#[no_mangle]
pub extern "C" fn lg_numbers() -> usize {
    PAGE.with_borrow(|page| page.numbers.as_ptr() as usize)
}

/// The address of the text [`lg_take_error`], [`lg_scenario`] or [`lg_world_scenario`] wrote.
#[no_mangle]
pub extern "C" fn lg_text() -> usize {
    PAGE.with_borrow(|page| page.text.as_ptr() as usize)
}

/// The length in bytes of the text at [`lg_text`].
#[no_mangle]
pub extern "C" fn lg_text_len() -> u32 {
    PAGE.with_borrow(|page| u32::try_from(page.text.len()).unwrap_or(0))
}

/// Panel `panel`'s relative energy error.
#[no_mangle]
pub extern "C" fn lg_energy_error(panel: u32) -> f64 {
    with_panel(panel, 0.0, |p| p.energy_error())
}

/// Panel `panel`'s status: 0 awake, 1 asleep, 2 set aside.
#[no_mangle]
pub extern "C" fn lg_status(panel: u32) -> u32 {
    with_panel(panel, 2, |p| p.status())
}

/// Panel `panel`'s scene time, s.
#[no_mangle]
pub extern "C" fn lg_time(panel: u32) -> f64 {
    with_panel(panel, 0.0, |p| p.time())
}

/// Panel `panel`'s fixed step, s.
#[no_mangle]
pub extern "C" fn lg_dt(panel: u32) -> f64 {
    with_panel(panel, 0.0, |p| p.dt())
}

/// Sets panel `panel`'s fixed step to `dt` s (0 or 1; on an error the panel is reset).
#[no_mangle]
pub extern "C" fn lg_set_dt(panel: u32, dt: f64) -> u32 {
    with_panel(panel, 1, |p| code(p.set_dt(dt)))
}

/// Restarts panel `panel` with integrator `method` (0 RK4, 1 Stormer-Verlet, 2
/// semi-implicit Euler).
#[no_mangle]
pub extern "C" fn lg_set_method(panel: u32, method: u32) -> u32 {
    PAGE.with_borrow_mut(
        |page| match page.set_method(panel as usize, method as usize) {
            Ok(()) => 0,
            Err(e) => {
                page.text = e.to_string();
                1
            }
        },
    )
}

/// Drags point `point` of panel `panel`'s main instance to the velocity `(vx, vy)` m/s.
#[no_mangle]
pub extern "C" fn lg_drag(panel: u32, point: u32, vx: f64, vy: f64) -> u32 {
    with_panel(panel, 1, |p| code(p.drag(point as usize, vx, vy)))
}

/// Sets panel `panel`'s input (the cart-pole's force, N).
#[no_mangle]
pub extern "C" fn lg_input(panel: u32, value: f64) -> u32 {
    with_panel(panel, 1, |p| code(p.set_input(value)))
}

/// The worst work of any contact step of panel `panel` since the page loaded: `which` 0 the
/// rows solved, 1 the rounds of the solves (0 for a panel without contacts).
#[no_mangle]
pub extern "C" fn lg_work(panel: u32, which: u32) -> u32 {
    with_panel(panel, 0, |p| {
        p.work().get(which as usize).copied().unwrap_or(0)
    })
}

/// The cap on the rounds of a contact step on the page (see `ImpulseStepper`'s work).
#[no_mangle]
pub extern "C" fn lg_rounds_cap() -> u32 {
    crate::setups::CONTACT_ROUNDS_CAP
}

/// Resets panel `panel` to its start.
#[no_mangle]
pub extern "C" fn lg_reset(panel: u32) {
    with_panel(panel, (), |p| p.reset());
}

/// Takes panel `panel`'s last error into [`lg_text`]: its length in bytes (0: none).
#[no_mangle]
pub extern "C" fn lg_take_error(panel: u32) -> u32 {
    PAGE.with_borrow_mut(|page| {
        let error = page
            .panels
            .get_mut(panel as usize)
            .and_then(|p| p.take_error());
        page.text = error.map(|e| e.to_string()).unwrap_or_default();
        u32::try_from(page.text.len()).unwrap_or(0)
    })
}

/// Runs the scripted scenario in `f64` (`double` = 1) or `f32` into [`lg_text`] (see
/// [`scenario::text`]): its length in bytes.
#[no_mangle]
pub extern "C" fn lg_scenario(double: u32) -> u32 {
    let text = scenario::text(double != 0);
    PAGE.with_borrow_mut(|page| {
        page.text = text;
        u32::try_from(page.text.len()).unwrap_or(0)
    })
}

/// Runs the world's lockstep case into [`lg_text`] (see [`scenario::world_text`]): its length
/// in bytes.
#[no_mangle]
pub extern "C" fn lg_world_scenario() -> u32 {
    let text = scenario::world_text();
    PAGE.with_borrow_mut(|page| {
        page.text = text;
        u32::try_from(page.text.len()).unwrap_or(0)
    })
}

/// Runs `f` on the page's sandbox (`script`: the scripted run's) or returns `missing`; an
/// error `f` returns is kept as the page's text and answered with `failed`.
fn with_sandbox<R>(
    script: bool,
    missing: R,
    failed: R,
    f: impl FnOnce(&mut AnySandbox) -> Result<R, Error>,
) -> R {
    PAGE.with_borrow_mut(|page| {
        let slot = if script {
            &mut page.script
        } else {
            &mut page.sandbox
        };
        let Some(sandbox) = slot.as_mut() else {
            return missing;
        };
        match f(sandbox) {
            Ok(r) => r,
            Err(e) => {
                page.text = e.to_string();
                failed
            }
        }
    })
}

/// Builds the sandbox in `f64` (`double` = 1) or `f32` (and the scripted run's, at its
/// start): 0, or 1 with the error in [`lg_text`].
#[no_mangle]
pub extern "C" fn lg_sandbox_init(double: u32) -> u32 {
    PAGE.with_borrow_mut(|page| {
        match (AnySandbox::new(double != 0), AnySandbox::new(double != 0)) {
            (Ok(sandbox), Ok(script)) => {
                page.sandbox = Some(sandbox);
                page.script = Some(script);
                0
            }
            (Err(e), _) | (_, Err(e)) => {
                page.text = e.to_string();
                1
            }
        }
    })
}

/// Advances the sandbox by `frame_time` s: the steps taken, or `u32::MAX` when one failed
/// (the sandbox is then rebuilt; the error in [`lg_text`]).
#[no_mangle]
pub extern "C" fn lg_sandbox_advance(frame_time: f64) -> u32 {
    let steps = with_sandbox(false, 0, u32::MAX, |s| s.advance(frame_time));
    if steps == u32::MAX {
        PAGE.with_borrow_mut(|page| {
            let double = matches!(page.sandbox, Some(AnySandbox::Double(_)));
            page.sandbox = AnySandbox::new(double).ok();
        });
    }
    steps
}

/// Writes the sandbox's shapes to [`lg_numbers`] (see `Sandbox::shapes`): the count of
/// numbers.
#[no_mangle]
pub extern "C" fn lg_sandbox_shapes() -> u32 {
    PAGE.with_borrow_mut(|page| {
        let Page {
            sandbox, numbers, ..
        } = page;
        numbers.clear();
        if let Some(s) = sandbox {
            s.shapes(numbers);
        }
        u32::try_from(numbers.len()).unwrap_or(0)
    })
}

/// The key of the body under `(x, y)` plus one, or 0 for none.
#[no_mangle]
pub extern "C" fn lg_sandbox_grab(x: f64, y: f64) -> u32 {
    with_sandbox(false, 0, 0, |s| {
        Ok(s.grab(x, y).map_or(0, |k| k.saturating_add(1)))
    })
}

/// Throws body `key` at `(vx, vy)` m/s: 0, or 1 with the error in [`lg_text`].
#[no_mangle]
pub extern "C" fn lg_sandbox_throw(key: u32, vx: f64, vy: f64) -> u32 {
    with_sandbox(false, 1, 1, |s| s.throw(key, vx, vy).map(|()| 0))
}

/// The sandbox's figure `which` of `[bodies, awake, contacts of the last step, the most of
/// any step, the cap]`, of the scripted run's where `script` = 1.
#[no_mangle]
pub extern "C" fn lg_sandbox_info(script: u32, which: u32) -> u32 {
    with_sandbox(script != 0, 0, 0, |s| {
        Ok(s.info().get(which as usize).copied().unwrap_or(0))
    })
}

/// Step `i` of the scripted run: 0, or 1 with the error in [`lg_text`].
#[no_mangle]
pub extern "C" fn lg_script_step(i: u32) -> u32 {
    with_sandbox(true, 1, 1, |s| s.script_step(i).map(|()| 0))
}

/// The steps of the scripted run.
#[no_mangle]
pub extern "C" fn lg_script_steps() -> u32 {
    SCRIPT_STEPS
}

/// The scripted run's digest as text in [`lg_text`] (`"<hex>"`): its length.
#[no_mangle]
pub extern "C" fn lg_script_digest() -> u32 {
    PAGE.with_borrow_mut(|page| {
        page.text = page
            .script
            .as_ref()
            .map_or_else(String::new, |s| format!("{:016x}", s.digest()));
        u32::try_from(page.text.len()).unwrap_or(0)
    })
}
