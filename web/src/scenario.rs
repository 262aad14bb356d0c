//! The scripted scenario the page runs to show that its bits are the host's and the
//! firmware's: the lockstep case `lagrange_cases::scripted` (a scene of damped pendulums and
//! cart-poles that fall asleep and are woken by an impulse, a state write, inputs, a removal,
//! an explicit wake, a contact and a parameter change), the same function the Cortex-M4F runs
//! under QEMU (`cargo xtask qemu`) and the host checks it against. And the world's lockstep
//! case, `lagrange_cases::world_in_a_box` (three balls and a crate dropped into a box: they
//! bounce, touch, rest and sleep), likewise.

use lagrange_cases::{scripted, world_in_a_box, Outcome, STEPS};
use lagrange_core::Error;

/// Frames of the scenario: the lockstep comparison's.
pub const FRAMES: u32 = STEPS;

/// The outcome words of the scenario in `f32` (`double` false) or `f64`: the digest of every
/// instance's bits and status, the two awake counts, the scene's time bits.
///
/// # Errors
/// The scenario's own errors (none for its values).
pub fn words(double: bool) -> Result<Vec<u64>, Error> {
    let outcome: Outcome = if double {
        scripted::<f64>(FRAMES)?
    } else {
        scripted::<f32>(FRAMES)?
    };
    Ok(outcome.words().to_vec())
}

/// FNV-1a over the words: one number to show.
#[must_use]
pub fn digest(words: &[u64]) -> u64 {
    words.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &w| {
        (hash ^ w).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The outcome words of the world's case (`f32`, [`FRAMES`] steps): the digest of every
/// body's bits, and how many are asleep.
///
/// # Errors
/// The world's own errors (none for its values).
pub fn world_words() -> Result<Vec<u64>, Error> {
    Ok(world_in_a_box(FRAMES)?.words().to_vec())
}

/// The line the page shows for the world's case: `"world frames=1000 words=<hex>,...
/// digest=<hex>"`, or `"world error: ..."`.
#[must_use]
pub fn world_text() -> String {
    line("world", world_words())
}

/// `"<name> frames=1000 words=<hex>,<hex>,... digest=<hex>"`, or `"<name> error: ..."`.
fn line(name: &str, words: Result<Vec<u64>, Error>) -> String {
    match words {
        Ok(words) => {
            let list: Vec<String> = words.iter().map(|w| format!("{w:016x}")).collect();
            format!(
                "{name} frames={FRAMES} words={} digest={:016x}",
                list.join(","),
                digest(&words)
            )
        }
        Err(e) => format!("{name} error: {e}"),
    }
}

/// What the page shows, and what `cargo xtask web --test` reads:
/// `"f32 frames=1000 words=<hex>,<hex>,... digest=<hex>"`, or `"f32 error: ..."`.
#[must_use]
pub fn text(double: bool) -> String {
    line(if double { "f64" } else { "f32" }, words(double))
}
