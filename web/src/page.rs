//! [`Page`]: every panel of the page, the precision they run in, and the buffers the
//! exports hand to JavaScript.

use lagrange_core::Error;

use crate::setups::{make, KINDS};
use crate::sim::Panel;

/// The page's state.
#[derive(Default)]
pub struct Page {
    /// `true`: the panels run in `f64`; `false`: `f32`.
    pub double: bool,
    /// One per entry of [`KINDS`].
    pub panels: Vec<Box<dyn Panel>>,
    /// The integrator of each panel (an index of `setups::METHODS`).
    pub methods: Vec<usize>,
    /// Numbers for the page: counts then coordinates.
    pub numbers: Vec<f64>,
    /// Text for the page (UTF-8).
    pub text: String,
    /// The sandbox the page shows.
    pub sandbox: Option<crate::sandbox::AnySandbox>,
    /// The sandbox of the scripted run the test drives, step by step.
    pub script: Option<crate::sandbox::AnySandbox>,
}

impl Page {
    /// Every panel in `f64` (`double`) or `f32`, with the integrators chosen so far (RK4 at
    /// first).
    ///
    /// # Errors
    /// A panel's construction error.
    pub fn init(&mut self, double: bool) -> Result<(), Error> {
        self.double = double;
        self.methods.resize(KINDS.len(), 0);
        self.panels = (0..KINDS.len())
            .map(|k| self.build(k))
            .collect::<Result<_, _>>()?;
        Ok(())
    }

    /// Panel `kind` in the page's precision with its chosen integrator.
    ///
    /// # Errors
    /// Its construction error.
    pub fn build(&self, kind: usize) -> Result<Box<dyn Panel>, Error> {
        let method = self.methods.get(kind).copied().unwrap_or(0);
        if self.double {
            make::<f64>(kind, method)
        } else {
            make::<f32>(kind, method)
        }
    }

    /// Steps panel `kind` with integrator `method` from its start.
    ///
    /// # Errors
    /// Its construction error, or [`Error::InvalidParameter`] for an unknown panel.
    pub fn set_method(&mut self, kind: usize, method: usize) -> Result<(), Error> {
        let slot = self.methods.get_mut(kind).ok_or(Error::InvalidParameter {
            name: "panel",
            reason: "no such panel",
        })?;
        *slot = method;
        let panel = self.build(kind)?;
        if let Some(p) = self.panels.get_mut(kind) {
            *p = panel;
        }
        Ok(())
    }
}
