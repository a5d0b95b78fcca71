//! Supports: SPC1 and SPC.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::Value;

/// Grids of a support card: listed ones must exist; a THRU range takes the grids that exist
/// in it (as Nastran does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Grids {
    /// One grid.
    One(u32),
    /// All existing grids from..=to.
    Range(u32, u32),
}

/// One support entry: set id, grids, components.
pub type Support = (u32, Grids, [bool; 6]);

/// SPC1 / SPC with zero enforced displacement.
pub(crate) fn spc1(r: &Reader) -> Result<Vec<Support>, FeError> {
    let sid = r.id(0, "SID")?;
    let comps = r.components(1, "C")?;
    let mut out = Vec::new();
    if matches!(r.value(3, "THRU")?, Value::Text(ref t) if t == "THRU") {
        r.at_most(5)?;
        let (from, to) = (r.id(2, "G1")?, r.id(4, "G2")?);
        if to < from {
            return Err(r.error(4, "G2", format!("THRU range {from} to {to} is empty")));
        }
        out.push((sid, Grids::Range(from, to), comps));
    } else {
        for i in 2..r.len() {
            if let Some(g) = r.opt_id(i, "Gi")? {
                out.push((sid, Grids::One(g), comps));
            }
        }
    }
    if out.is_empty() {
        return Err(r.card_error("no grid listed"));
    }
    Ok(out)
}

pub(crate) fn spc(r: &Reader) -> Result<Vec<Support>, FeError> {
    r.at_most(7)?;
    let sid = r.id(0, "SID")?;
    let mut out = Vec::new();
    for k in [1, 4] {
        if let Some(g) = r.opt_id(k, "Gi")? {
            let d = r.real_or(k + 2, "Di", 0.0)?;
            if d != 0.0 {
                return Err(r.error(
                    k + 2,
                    "Di",
                    "enforced displacement is not supported (supports are fixed)",
                ));
            }
            out.push((sid, Grids::One(g), r.components(k + 1, "Ci")?));
        }
    }
    if out.is_empty() {
        return Err(r.card_error("no grid listed"));
    }
    Ok(out)
}
