//! # lagrange-web
//!
//! The library compiled to WebAssembly for the interactive page (`cargo xtask web`): seven
//! mechanisms, each in a scene with one fixed-timestep clock, stepped from the browser's
//! frame times and drawn from interpolated states by `web/site/app.js`; an integrator and a
//! step for each, `f32` or `f64`; drags (impulses), the cart-pole's input, the scripted
//! scenario whose bits the page shows ([`scenario`]), and a sandbox of bodies that touch each
//! other in one `lagrange_world::World` ([`sandbox`]).
//!
//! The exports are plain C ABI functions of numbers (module [`exports`]); arrays come back
//! through a buffer whose address an export returns, read by the page as a `Float64Array`
//! (points) or UTF-8 (text). There is no `unsafe` block: the state lives in a thread-local
//! (WebAssembly runs the page on one thread).
//!
//! ```
//! use lagrange_web::setups::{make, KINDS};
//! let mut panel = make::<f64>(0, 0)?; // the origin's pendulum, RK4
//! panel.advance(1.0 / 60.0);
//! let mut points = Vec::new();
//! let counts = panel.points(&mut points);
//! assert_eq!((counts.main, counts.exact), (2, 2));
//! assert_eq!(KINDS.len(), 7);
//! # Ok::<(), lagrange_core::Error>(())
//! ```

pub mod exports;
pub mod page;
pub mod sandbox;
pub mod scenario;
pub mod setups;
pub mod sim;
