//! Modal damping of the reduced body, as engineering data.
//!
//! Two things are kept apart here:
//! - the **physical** damping of the body's modes: a table of damping against frequency with
//!   Nastran's `TABDMP1` semantics ([`DampingTable`]) and overrides for single modes by number
//!   ([`BodyDamping::modes`]);
//! - a **numerical** device: the modes above the fixed-interface cut-off are the interface
//!   (constraint) modes of the Craig-Bampton basis, whose frequencies follow from the reduction,
//!   not from the structure. Damping them heavily keeps their static compliance (the body's
//!   static response at the mounts stays exact) and removes their dynamics, which is what keeps
//!   the coupled model cheap for the integrator ([`BodyDamping::above_cutoff`]).
//!
//! The ADAMS fallback (1 % below 100 Hz, 10 % below 1 kHz, 100 % above, what MSC Adams applies
//! to a flexible body given no damping) stays available as [`DampingTable::adams`] and
//! [`BodyDamping::adams`].

use serde::{Deserialize, Serialize};

use super::error::CmsError;

/// What the values of a [`DampingTable`] are (Nastran `TABDMP1` field TYPE).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DampingUnit {
    /// Fraction of critical damping ζ (`CRIT`).
    Crit,
    /// Structural damping coefficient g = 2ζ (`G`, Nastran's default).
    G,
    /// Quality factor Q = 1 / (2ζ) (`Q`).
    Q,
}

impl DampingUnit {
    /// The Nastran spelling (`CRIT`, `G`, `Q`).
    pub fn nastran(self) -> &'static str {
        match self {
            DampingUnit::Crit => "CRIT",
            DampingUnit::G => "G",
            DampingUnit::Q => "Q",
        }
    }

    /// The unit by its Nastran spelling (case-insensitive; blank is `G`, Nastran's default).
    pub fn from_nastran(text: &str) -> Option<Self> {
        match text.trim().to_ascii_uppercase().as_str() {
            "" | "G" => Some(DampingUnit::G),
            "CRIT" => Some(DampingUnit::Crit),
            "Q" => Some(DampingUnit::Q),
            _ => None,
        }
    }

    /// The damping ratio (fraction of critical) of a value in this unit.
    pub fn ratio(self, value: f64) -> f64 {
        match self {
            DampingUnit::Crit => value,
            DampingUnit::G => 0.5 * value,
            DampingUnit::Q => 0.5 / value,
        }
    }
}

/// What is wrong with a [`DampingTable`]: the point (0-based, if one is at fault) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct TableError {
    /// The offending point.
    pub point: Option<usize>,
    /// What is wrong with it.
    pub message: String,
}

impl std::fmt::Display for TableError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.point {
            Some(i) => write!(f, "point {i}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

/// The damping a body brings with it (a deck's `TABDMP1` named by `SDAMPING`), applied unless
/// the vehicle configuration gives the body a damping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OwnDamping {
    /// Where it comes from, for the log (`TABDMP1 12 at line 40 of body.bdf`).
    pub source: String,
    /// The table.
    pub table: DampingTable,
}

/// Damping against natural frequency, as Nastran's `TABDMP1`: pairs (frequency in Hz, value in
/// [`DampingUnit`]), linear interpolation of the values between the points, the end values held
/// outside the table. Two points at the same frequency make a step; exactly at the step the mean
/// of the two values applies (as in Nastran). The value is interpolated first and then turned
/// into a damping ratio (for `Q` the ratio is therefore not linear between the points).
///
/// Outside the table MSC and Simcenter Nastran extrapolate linearly from the two end points,
/// OptiStruct holds the end values with `FLAT = 1`: the ends are held here, so that no mode gets
/// a damping that no one wrote down (a table ending on a slope would extrapolate to negative
/// damping).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingTable {
    /// What the values are.
    #[serde(rename = "type")]
    pub unit: DampingUnit,
    /// (frequency in Hz, value) pairs, frequencies ascending (two equal ones make a step).
    pub points: Vec<[f64; 2]>,
}

impl Default for DampingTable {
    /// The ADAMS fallback ([`DampingTable::adams`]): what a [`crate::cms::ReductionSpec`] applies
    /// unless told otherwise.
    fn default() -> Self {
        Self::adams()
    }
}

impl DampingTable {
    /// The same damping ratio for every mode.
    pub fn uniform(zeta: f64) -> Self {
        Self {
            unit: DampingUnit::Crit,
            points: vec![[0.0, zeta]],
        }
    }

    /// What MSC Adams applies to a flexible body when the user gives no damping (Adams Solver
    /// `FLEX_BODY`, `CRATIO` default): 1 % below 100 Hz, 10 % from 100 Hz to 1 kHz, 100 % above.
    /// A solver's fallback, kept for comparison with Adams results, not an engineering value.
    pub fn adams() -> Self {
        Self {
            unit: DampingUnit::Crit,
            points: vec![[100.0, 0.01], [100.0, 0.10], [1000.0, 0.10], [1000.0, 1.0]],
        }
    }

    /// This table with every damping ratio multiplied by `factor` (the values of a `Q` table
    /// divided by it).
    pub fn scaled(&self, factor: f64) -> Self {
        let value = |v: f64| match self.unit {
            DampingUnit::Q => v / factor,
            DampingUnit::Crit | DampingUnit::G => v * factor,
        };
        Self {
            unit: self.unit,
            points: self.points.iter().map(|&[f, v]| [f, value(v)]).collect(),
        }
    }

    /// Checks the table; the error names the offending point (0-based) and its value.
    /// At least one point; frequencies finite, >= 0 and ascending, at most two equal ones in a
    /// row (a step); values finite and >= 0 (`Q`: > 0).
    pub fn check(&self) -> Result<(), TableError> {
        let unit = self.unit.nastran();
        let at = |i: usize, message: String| {
            Err(TableError {
                point: Some(i),
                message,
            })
        };
        if self.points.is_empty() {
            return Err(TableError {
                point: None,
                message: "the table has no point (at least one frequency and value)".into(),
            });
        }
        for (i, &[f, v]) in self.points.iter().enumerate() {
            if !(f.is_finite() && f >= 0.0) {
                return at(i, format!("frequency {f} Hz must be finite and >= 0"));
            }
            if i > 0 {
                let before = self.points[i - 1][0];
                if f < before {
                    return at(
                        i,
                        format!(
                            "frequency {f} Hz is below the one before it ({before} Hz); \
                             frequencies must increase (two equal ones make a step)"
                        ),
                    );
                }
                if i > 1 && f == before && f == self.points[i - 2][0] {
                    return at(
                        i,
                        format!(
                            "a third value at {f} Hz; a step takes two points at one frequency"
                        ),
                    );
                }
            }
            let bad = match self.unit {
                DampingUnit::Q => !(v.is_finite() && v > 0.0),
                DampingUnit::Crit | DampingUnit::G => !(v.is_finite() && v >= 0.0),
            };
            if bad {
                let need = if self.unit == DampingUnit::Q {
                    "finite and > 0 (Q = 1/(2 zeta))"
                } else {
                    "finite and >= 0"
                };
                return at(i, format!("{unit} value {v} at {f} Hz must be {need}"));
            }
        }
        Ok(())
    }

    /// [`DampingTable::check`] as a reduction error.
    pub fn validate(&self) -> Result<(), CmsError> {
        self.check()
            .map_err(|e| CmsError::InvalidInput(format!("damping table: {e}")))
    }

    /// The table's value (in its own unit) at `frequency_hz`.
    pub fn value(&self, frequency_hz: f64) -> f64 {
        let p = &self.points;
        let Some(j) = p.iter().position(|&[f, _]| f >= frequency_hz) else {
            return p.last().map_or(0.0, |q| q[1]);
        };
        let [fj, vj] = p[j];
        if fj == frequency_hz {
            return match p.get(j + 1) {
                Some(&[f_next, v_next]) if f_next == fj => 0.5 * (vj + v_next),
                _ => vj,
            };
        }
        if j == 0 {
            return vj;
        }
        let [fi, vi] = p[j - 1];
        let s = (frequency_hz - fi) / (fj - fi);
        vi + s * (vj - vi)
    }

    /// The damping ratio (fraction of critical) of a mode with natural frequency `frequency_hz`.
    pub fn ratio(&self, frequency_hz: f64) -> f64 {
        self.unit.ratio(self.value(frequency_hz))
    }
}

/// The modal damping of a reduced body: the physical table and per-mode overrides, and the
/// numerical damping of the interface modes above the fixed-interface cut-off.
///
/// The damping ratio of mode `k` (numbered from 1, ascending frequency `f_k`) is
/// - `modes[k]` if given (an override is final), else
/// - `table(f_k)`, and for a mode above the cut-off at least `above_cutoff(f_k)`.
///
/// A scale (the FMU's `chassis.modalDampingScale`) multiplies the physical part, the table and
/// the overrides, not the numerical one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDamping {
    /// Physical: damping of each mode by its natural frequency.
    pub table: DampingTable,
    /// Physical: (mode number, damping ratio) of single modes, 1 being the lowest mode of the
    /// reduced body, the ratio a fraction of critical, in place of the table's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<(usize, f64)>,
    /// Numerical: the least damping of the modes above the fixed-interface cut-off (the
    /// interface modes), by frequency (default: 10 % below 1 kHz, 100 % above).
    #[serde(default = "interface_mode_damping")]
    pub above_cutoff: DampingTable,
}

/// The numerical damping of the interface modes: 10 % below 1 kHz, 100 % above (the upper two
/// bands of the ADAMS fallback, which set the model's speed until now).
fn interface_mode_damping() -> DampingTable {
    DampingTable {
        unit: DampingUnit::Crit,
        points: vec![[1000.0, 0.10], [1000.0, 1.0]],
    }
}

/// The default physical damping ratio of the body's modes: 5 % of critical, the middle of the
/// 3–7 % that engineering references give for metal structures with joints (Adams & Askenazi,
/// *Building Better Products with Finite Element Analysis*, 1999), where a trimmed body with a
/// bolted steering column belongs; the guide's page on damping gives the sources and the range.
pub const DEFAULT_BODY_DAMPING_RATIO: f64 = 0.05;

impl Default for BodyDamping {
    /// [`DEFAULT_BODY_DAMPING_RATIO`] for every mode, the interface modes damped numerically.
    fn default() -> Self {
        Self {
            table: DampingTable::uniform(DEFAULT_BODY_DAMPING_RATIO),
            modes: Vec::new(),
            above_cutoff: interface_mode_damping(),
        }
    }
}

impl BodyDamping {
    /// The ADAMS fallback as a body damping: every mode as [`DampingTable::adams`] (the
    /// interface modes get the same 10 % / 100 %).
    pub fn adams() -> Self {
        Self {
            table: DampingTable::adams(),
            modes: Vec::new(),
            above_cutoff: interface_mode_damping(),
        }
    }

    /// This damping from `table`, the interface modes damped numerically as by default.
    pub fn from_table(table: DampingTable) -> Self {
        Self {
            table,
            ..Self::default()
        }
    }

    /// Checks both tables and the overrides; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        self.table.check().map_err(|e| format!("table: {e}"))?;
        self.above_cutoff
            .check()
            .map_err(|e| format!("above_cutoff: {e}"))?;
        for (i, &(mode, zeta)) in self.modes.iter().enumerate() {
            if mode == 0 {
                return Err(format!(
                    "modes[{i}]: mode 0 does not exist (modes are numbered from 1)"
                ));
            }
            if self.modes[..i].iter().any(|&(m, _)| m == mode) {
                return Err(format!("modes[{i}]: mode {mode} is given twice"));
            }
            if !(zeta.is_finite() && zeta >= 0.0) {
                return Err(format!(
                    "modes[{i}]: damping ratio {zeta} of mode {mode} must be finite and >= 0"
                ));
            }
        }
        Ok(())
    }

    /// The damping ratio of every mode of a body with these natural frequencies (Hz,
    /// ascending), whose modes above `cutoff_hz` are interface modes (`None`: none is), the
    /// physical part multiplied by `scale`.
    pub fn ratios(
        &self,
        frequencies_hz: &[f64],
        cutoff_hz: Option<f64>,
        scale: f64,
    ) -> Result<Vec<f64>, String> {
        self.check()?;
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(format!("scale {scale} must be finite and >= 0"));
        }
        let n = frequencies_hz.len();
        if let Some((i, &(mode, _))) = self.modes.iter().enumerate().find(|(_, m)| m.0 > n) {
            return Err(format!(
                "modes[{i}]: mode {mode}, but the body has {n} modes (numbered 1 to {n})"
            ));
        }
        Ok(frequencies_hz
            .iter()
            .enumerate()
            .map(|(k, &f)| {
                if let Some(&(_, zeta)) = self.modes.iter().find(|m| m.0 == k + 1) {
                    return scale * zeta;
                }
                let physical = scale * self.table.ratio(f);
                match cutoff_hz {
                    Some(c) if f > c => physical.max(self.above_cutoff.ratio(f)),
                    _ => physical,
                }
            })
            .collect())
    }
}

/// The damping ratio of each mode by the table: shared by every body, reduced here or elsewhere.
pub(crate) fn table_damping(omega: &[f64], damping: &DampingTable) -> Vec<f64> {
    omega
        .iter()
        .map(|w| damping.ratio(w / (2.0 * std::f64::consts::PI)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(unit: DampingUnit, points: &[[f64; 2]]) -> DampingTable {
        DampingTable {
            unit,
            points: points.to_vec(),
        }
    }

    #[test]
    fn adams_table_is_the_old_step_function() {
        let t = DampingTable::adams();
        assert!(t.check().is_ok());
        assert_eq!(t.ratio(0.5), 0.01);
        assert_eq!(t.ratio(31.0), 0.01);
        assert_eq!(t.ratio(99.999), 0.01);
        assert_eq!(t.ratio(100.001), 0.10);
        assert_eq!(t.ratio(999.0), 0.10);
        assert_eq!(t.ratio(1000.001), 1.0);
        assert_eq!(t.ratio(5.0e4), 1.0);
        // Exactly at a step, Nastran's mean of the two values.
        assert!((t.ratio(100.0) - 0.055).abs() < 1e-15);
        assert!((t.ratio(1000.0) - 0.55).abs() < 1e-15);
    }

    #[test]
    fn values_are_interpolated_in_their_unit_and_held_at_the_ends() {
        let g = table(DampingUnit::G, &[[10.0, 0.02], [20.0, 0.06], [40.0, 0.06]]);
        assert_eq!(g.ratio(5.0), 0.01);
        assert!((g.ratio(15.0) - 0.02).abs() < 1e-15);
        assert!((g.ratio(12.5) - 0.015).abs() < 1e-15);
        assert_eq!(g.ratio(30.0), 0.03);
        assert_eq!(g.ratio(1e6), 0.03);
        // Q is interpolated as Q: halfway between Q = 10 and Q = 50 is Q = 30.
        let q = table(DampingUnit::Q, &[[10.0, 10.0], [20.0, 50.0]]);
        assert!((q.ratio(15.0) - 1.0 / 60.0).abs() < 1e-15);
        assert_eq!(q.ratio(0.0), 0.05);
        assert_eq!(q.ratio(100.0), 0.01);
        let one = table(DampingUnit::Crit, &[[50.0, 0.04]]);
        for f in [0.0, 50.0, 1e4] {
            assert_eq!(one.ratio(f), 0.04);
        }
    }

    #[test]
    fn scaling_multiplies_every_ratio() {
        let t = DampingTable::adams().scaled(2.0);
        assert_eq!(t.ratio(50.0), 0.02);
        assert_eq!(t.ratio(500.0), 0.2);
        assert_eq!(t.ratio(2000.0), 2.0);
        let q = table(DampingUnit::Q, &[[0.0, 25.0]]).scaled(2.0);
        assert!((q.ratio(3.0) - 0.04).abs() < 1e-15);
        assert_eq!(DampingTable::uniform(0.03).ratio(1.0e6), 0.03);
    }

    #[test]
    fn bad_tables_are_named() {
        let e = |t: DampingTable| t.check().unwrap_err().to_string();
        assert!(e(table(DampingUnit::Crit, &[])).contains("no point"));
        let m = e(table(DampingUnit::Crit, &[[10.0, 0.01], [5.0, 0.02]]));
        assert!(m.contains("point 1") && m.contains("increase"), "{m}");
        let m = e(table(DampingUnit::G, &[[10.0, 0.01], [20.0, -0.02]]));
        assert!(m.contains("point 1") && m.contains("G value -0.02"), "{m}");
        let m = e(table(DampingUnit::Crit, &[[10.0, f64::NAN]]));
        assert!(m.contains("point 0"), "{m}");
        let m = e(table(DampingUnit::Crit, &[[f64::INFINITY, 0.01]]));
        assert!(m.contains("frequency inf"), "{m}");
        let m = e(table(DampingUnit::Q, &[[10.0, 0.0]]));
        assert!(m.contains("Q value 0"), "{m}");
        let m = e(table(
            DampingUnit::Crit,
            &[[10.0, 0.01], [10.0, 0.02], [10.0, 0.03]],
        ));
        assert!(m.contains("point 2") && m.contains("third"), "{m}");
        assert!(DampingTable::uniform(-0.1)
            .validate()
            .unwrap_err()
            .to_string()
            .contains("damping table"));
    }

    #[test]
    fn nastran_spellings() {
        for u in [DampingUnit::Crit, DampingUnit::G, DampingUnit::Q] {
            assert_eq!(DampingUnit::from_nastran(u.nastran()), Some(u));
        }
        assert_eq!(DampingUnit::from_nastran(" crit "), Some(DampingUnit::Crit));
        assert_eq!(DampingUnit::from_nastran(""), Some(DampingUnit::G));
        assert_eq!(DampingUnit::from_nastran("KDAMP"), None);
    }

    #[test]
    fn body_damping_keeps_the_physical_and_the_numerical_apart() {
        let hz = [1.2, 31.3, 150.0, 238.0, 1197.0];
        let d = BodyDamping::default();
        let z = d.ratios(&hz, Some(225.0), 1.0).unwrap();
        assert_eq!(z, vec![0.05, 0.05, 0.05, 0.10, 1.0]);
        // The scale acts on the physical part only.
        let z = d.ratios(&hz, Some(225.0), 0.0).unwrap();
        assert_eq!(z, vec![0.0, 0.0, 0.0, 0.10, 1.0]);
        let z = d.ratios(&hz, Some(225.0), 3.0).unwrap();
        assert!((z[3] - 0.15).abs() < 1e-15 && z[4] == 1.0, "{z:?}");
        // Without a cut-off no mode is an interface mode.
        assert_eq!(d.ratios(&hz, None, 1.0).unwrap(), vec![0.05; 5]);
        // An override is final, and scaled.
        let mut o = d.clone();
        o.modes = vec![(2, 0.02), (5, 0.0)];
        let z = o.ratios(&hz, Some(225.0), 2.0).unwrap();
        assert_eq!(z, vec![0.10, 0.04, 0.10, 0.10, 0.0]);
        // The ADAMS preset reproduces the old table on the interface modes too.
        let a = BodyDamping::adams().ratios(&hz, Some(225.0), 1.0).unwrap();
        assert_eq!(a, vec![0.01, 0.01, 0.10, 0.10, 1.0]);
    }

    #[test]
    fn bad_body_damping_is_named() {
        let mut d = BodyDamping {
            modes: vec![(1, 0.01), (7, 0.03)],
            ..BodyDamping::default()
        };
        let e = d.ratios(&[10.0; 5], None, 1.0).unwrap_err();
        assert!(
            e.contains("modes[1]: mode 7") && e.contains("5 modes"),
            "{e}"
        );
        d.modes = vec![(0, 0.03)];
        assert!(d.check().unwrap_err().contains("mode 0"));
        d.modes = vec![(3, -1.0)];
        assert!(d.check().unwrap_err().contains("modes[0]"));
        d.modes = vec![(3, 0.01), (3, 0.02)];
        assert!(d.check().unwrap_err().contains("given twice"));
        let mut d = BodyDamping::default();
        d.above_cutoff.points.clear();
        assert!(d.check().unwrap_err().starts_with("above_cutoff"));
        assert!(BodyDamping::default()
            .ratios(&[1.0], None, f64::NAN)
            .is_err());
    }

    #[test]
    fn json_names_the_nastran_fields() {
        let d = BodyDamping::default();
        let text = serde_json::to_string(&d).unwrap();
        assert!(text.contains("\"type\":\"crit\""), "{text}");
        let back: BodyDamping = serde_json::from_str(&text).unwrap();
        assert_eq!(back, d);
        let parsed: BodyDamping = serde_json::from_str(
            r#"{"table": {"type": "g", "points": [[0, 0.06]]}, "modes": [[7, 0.02]],
                "above_cutoff": {"type": "crit", "points": [[0, 1.0]]}}"#,
        )
        .unwrap();
        assert_eq!(parsed.modes, vec![(7, 0.02)]);
        assert!((parsed.table.ratio(40.0) - 0.03).abs() < 1e-15);
    }
}
