//! Directional derivatives in initialisation mode: how the initial unknowns (the outputs of the
//! initialisation: the static equilibrium, or the periodic orbit) respond to a Real input.
//!
//! A host that solves an algebraic loop of connected FMUs during initialisation (OMSimulator
//! does, over the engine–body mounts) asks for them: it iterates the interface inputs and wants
//! the Jacobian of the initial outputs. Setting an input in initialisation mode re-solves the
//! initialisation, so the derivative is that of the whole initialisation (at the static
//! equilibrium the mount forces shift between the mounts and keep their sum), not the
//! instantaneous feedthrough of a communication point. It is computed by central differences of
//! the initialisation, one column per input and cached until a value changes: the equilibrium is
//! solved to round-off, and FMI 2.0 §2.1.9 permits numerical differentiation.

use super::bindings;
use super::instance::Instance;
use super::parameters;
use super::values::Num;
use crate::cosim::Runtime;
use crate::variables::REALS;

/// Relative step of the central difference (per unit of the input, at least 1 of its unit):
/// the initialisation is smooth and solved to round-off, so the truncation error of a step this
/// small stays below the round-off of the differences (checked against a host's own central
/// difference in tests/fmi/model_structure.rs).
const RELATIVE_STEP: f64 = 1e-6;

impl Instance {
    /// `∂(every Real)/∂(Real input k)` of the initialisation at the current parameters and
    /// inputs (only the outputs change), computed when first asked for.
    pub(super) fn initial_sensitivity(&mut self, k: usize) -> Result<Vec<f64>, String> {
        self.ensure_simulation()?;
        if let Some(column) = self.core.initial_sensitivities.get(&k) {
            return Ok(column.clone());
        }
        let u = self.core.inputs[k].preview(self.core.time).0;
        let h = RELATIVE_STEP * u.abs().max(1.0);
        // A perturbed input the model refuses (a bound of its declared range) falls back to a
        // one-sided difference.
        let at = self.core.values.reals.as_slice();
        let column = match (
            self.initial_outputs(k, u + h),
            self.initial_outputs(k, u - h),
        ) {
            (Ok(up), Ok(down)) => difference(&up, &down, 2.0 * h),
            (Ok(up), Err(_)) => difference(&up, at, h),
            (Err(_), Ok(down)) => difference(at, &down, h),
            (Err(e), Err(_)) => {
                return Err(format!(
                    "derivative with respect to {}: the initialisation fails around {}: {e}",
                    REALS[k].name,
                    Num(u)
                ))
            }
        };
        self.core.initial_sensitivities.insert(k, column.clone());
        Ok(column)
    }

    /// The Reals with the outputs of the initialisation that Real input `k` at `value` gives,
    /// the other inputs and the parameters as they are; the instance itself is not changed.
    fn initial_outputs(&self, k: usize, value: f64) -> Result<Vec<f64>, String> {
        let mut tracks = self.core.inputs.clone();
        tracks[k].set_value(value);
        let settings = self.settings_for(&self.core)?;
        let inputs = parameters::inputs_from(&tracks, self.core.time);
        let mut runtime = Runtime::new(self.kind, &settings, self.core.time, &inputs)
            .map_err(|e| parameters::message(&e))?;
        let outputs = runtime.outputs().map_err(|e| parameters::message(&e))?;
        let mut reals = self.core.values.reals.clone();
        bindings::put_outputs(&mut reals, &outputs);
        Ok(reals.as_slice().to_vec())
    }
}

fn difference(up: &[f64], down: &[f64], span: f64) -> Vec<f64> {
    up.iter().zip(down).map(|(a, b)| (a - b) / span).collect()
}
