//! Scalar springs and dampers: CELAS1, CELAS2, PELAS, CDAMP1, CDAMP2, PDAMP.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::Loc;

/// Magnitude of a scalar element: a property reference or a value on the card.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScalarValue {
    /// PELAS / PDAMP id.
    Property(u32),
    /// K or B given directly.
    Value(f64),
}

/// CELAS1/2, CDAMP1/2: scalar spring or damper between two grid components or to ground.
#[derive(Debug, Clone, PartialEq)]
pub struct Scalar {
    pub id: u32,
    pub value: ScalarValue,
    pub ends: Vec<(u32, usize)>,
    pub line: Loc,
}

pub(crate) fn scalar(r: &Reader, direct: bool, spring: bool) -> Result<Scalar, FeError> {
    let id = r.id(0, "EID")?;
    let value = if direct {
        if spring {
            // CELAS2: GE (structural damping) and S (stress coefficient) follow; GE is added
            // modally by the caller, like MAT1 GE.
            r.opt_real(6, "GE")?;
            r.opt_real(7, "S")?;
            r.at_most(8)?;
        } else {
            r.at_most(6)?;
        }
        ScalarValue::Value(r.real(1, "K/B")?)
    } else {
        r.at_most(6)?;
        ScalarValue::Property(r.opt_id(1, "PID")?.unwrap_or(id))
    };
    let mut ends = Vec::new();
    for (g, c) in [(2, 3), (4, 5)] {
        let name_g = format!("G{}", g / 2);
        let name_c = format!("C{}", g / 2);
        match r.opt_id_or_zero(g, &name_g)? {
            Some(grid) => ends.push((grid, r.component(c, &name_c)?)),
            None => r.require_blank(c, &name_c, "a component without a grid")?,
        }
    }
    if ends.is_empty() {
        return Err(r.card_error("needs at least one grid (G1 or G2)"));
    }
    Ok(Scalar {
        id,
        value,
        ends,
        line: r.card().loc(),
    })
}

/// PELAS (up to two properties per card) or PDAMP (up to four): `(pid, value)`.
pub(crate) fn scalar_properties(r: &Reader, per_entry: usize) -> Result<Vec<(u32, f64)>, FeError> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < r.len() {
        if let Some(pid) = r.opt_id(k, "PID")? {
            out.push((pid, r.real(k + 1, "K/B")?));
            for extra in 2..per_entry {
                r.opt_real(k + extra, "GE/S")?;
            }
        }
        k += per_entry;
    }
    r.at_most(8)?;
    if out.is_empty() {
        return Err(r.card_error("no property defined"));
    }
    Ok(out)
}
