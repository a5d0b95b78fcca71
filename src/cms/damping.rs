//! Modal damping by frequency band, as ADAMS assigns it to the modes of a flexible body.
//!
//! The default is ADAMS' own: 1 % below 100 Hz, 10 % from 100 Hz to 1 kHz, 100 % above. Heavily
//! damped high-frequency interface modes keep their static compliance but lose their dynamics,
//! which is what keeps the coupled model cheap for the integrator.

use serde::{Deserialize, Serialize};

use super::error::CmsError;

/// Damping ratio `zeta` for modes with a natural frequency below `below_hz` (and at or above the
/// previous band's limit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DampingBand {
    /// Upper frequency limit of the band (Hz), exclusive.
    pub below_hz: f64,
    /// Damping ratio (fraction of critical) in the band.
    pub zeta: f64,
}

/// Modal damping ratios as a step function of the natural frequency.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DampingTable {
    /// Bands in ascending order of `below_hz`.
    pub bands: Vec<DampingBand>,
    /// Damping ratio of modes at or above the last band's limit.
    pub above: f64,
}

impl Default for DampingTable {
    fn default() -> Self {
        Self {
            bands: vec![
                DampingBand {
                    below_hz: 100.0,
                    zeta: 0.01,
                },
                DampingBand {
                    below_hz: 1000.0,
                    zeta: 0.10,
                },
            ],
            above: 1.0,
        }
    }
}

impl DampingTable {
    /// The same damping ratio for every mode.
    pub fn uniform(zeta: f64) -> Self {
        Self {
            bands: Vec::new(),
            above: zeta,
        }
    }

    /// This table with every damping ratio multiplied by `factor` (e.g. to tune response peaks).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            bands: self
                .bands
                .iter()
                .map(|b| DampingBand {
                    below_hz: b.below_hz,
                    zeta: b.zeta * factor,
                })
                .collect(),
            above: self.above * factor,
        }
    }

    /// Checks that limits are finite, positive and strictly ascending and ratios finite and >= 0.
    pub fn validate(&self) -> Result<(), CmsError> {
        let bad = |m: String| Err(CmsError::InvalidInput(format!("damping table: {m}")));
        let mut previous = 0.0;
        for (i, b) in self.bands.iter().enumerate() {
            if !(b.below_hz.is_finite() && b.below_hz > previous) {
                return bad(format!(
                    "bands[{i}].below_hz = {} must be finite and above {previous}",
                    b.below_hz
                ));
            }
            if !(b.zeta.is_finite() && b.zeta >= 0.0) {
                return bad(format!(
                    "bands[{i}].zeta = {} must be finite and >= 0",
                    b.zeta
                ));
            }
            previous = b.below_hz;
        }
        if !(self.above.is_finite() && self.above >= 0.0) {
            return bad(format!("above = {} must be finite and >= 0", self.above));
        }
        Ok(())
    }

    /// Damping ratio of a mode with natural frequency `frequency_hz`.
    pub fn zeta(&self, frequency_hz: f64) -> f64 {
        self.bands
            .iter()
            .find(|b| frequency_hz < b.below_hz)
            .map_or(self.above, |b| b.zeta)
    }
}

/// The damping ratio of each mode by the table: shared by every body, reduced here or elsewhere.
pub(crate) fn table_damping(omega: &[f64], damping: &DampingTable) -> Vec<f64> {
    omega
        .iter()
        .map(|w| damping.zeta(w / (2.0 * std::f64::consts::PI)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_adams_table() {
        let t = DampingTable::default();
        assert!(t.validate().is_ok());
        assert_eq!(t.zeta(31.0), 0.01);
        assert_eq!(t.zeta(99.999), 0.01);
        assert_eq!(t.zeta(100.0), 0.10);
        assert_eq!(t.zeta(999.0), 0.10);
        assert_eq!(t.zeta(1000.0), 1.0);
        assert_eq!(t.zeta(5.0e4), 1.0);
    }

    #[test]
    fn scaling_multiplies_every_ratio() {
        let t = DampingTable::default().scaled(2.0);
        assert_eq!(t.zeta(50.0), 0.02);
        assert_eq!(t.zeta(500.0), 0.2);
        assert_eq!(t.zeta(2000.0), 2.0);
        assert_eq!(DampingTable::uniform(0.03).zeta(1.0e6), 0.03);
    }

    #[test]
    fn bad_tables_are_named() {
        let mut t = DampingTable::default();
        t.bands[1].below_hz = 50.0;
        let e = t.validate().unwrap_err().to_string();
        assert!(e.contains("bands[1].below_hz"), "{e}");
        let mut t = DampingTable::default();
        t.bands[0].zeta = f64::NAN;
        assert!(t
            .validate()
            .unwrap_err()
            .to_string()
            .contains("bands[0].zeta"));
        let t = DampingTable::uniform(-0.1);
        assert!(t.validate().unwrap_err().to_string().contains("above"));
    }
}
