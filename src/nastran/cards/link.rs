//! Rigid and interpolation elements: RBE2 and RBE3.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::{Loc, Value};

/// RBE2: rigid element.
#[derive(Debug, Clone, PartialEq)]
pub struct Rbe2 {
    pub id: u32,
    pub independent: u32,
    pub components: [bool; 6],
    pub dependent: Vec<u32>,
    pub line: Loc,
}

pub(crate) fn rbe2(r: &Reader) -> Result<Rbe2, FeError> {
    let mut dependent = Vec::new();
    let mut i = 3;
    while i < r.len() {
        match r.value(i, "GMi")? {
            Value::Blank => {}
            Value::Int(_) => dependent.push(r.id(i, "GMi")?),
            // ALPHA (and TREF) close the card: thermal expansion, not used.
            Value::Real(_) => {
                r.opt_real(i + 1, "TREF")?;
                r.at_most(i + 2)?;
                break;
            }
            Value::Text(t) => return Err(r.error(i, "GMi", format!("unexpected '{t}'"))),
        }
        i += 1;
    }
    if dependent.is_empty() {
        return Err(r.card_error("no dependent grid"));
    }
    Ok(Rbe2 {
        id: r.id(0, "EID")?,
        independent: r.id(1, "GN")?,
        components: r.components(2, "CM")?,
        dependent,
        line: r.card().loc(),
    })
}

/// RBE3: interpolation element.
#[derive(Debug, Clone, PartialEq)]
pub struct Rbe3 {
    pub id: u32,
    pub reference: u32,
    pub reference_components: [bool; 6],
    /// (weight, components, grids).
    pub groups: Vec<(f64, [bool; 6], Vec<u32>)>,
    pub line: Loc,
}

pub(crate) fn rbe3(r: &Reader) -> Result<Rbe3, FeError> {
    r.require_blank(1, "blank", "field 3 of RBE3 is unused")?;
    let mut groups: Vec<(f64, [bool; 6], Vec<u32>)> = Vec::new();
    let mut i = 4;
    while i < r.len() {
        match r.value(i, "WTi/Gi,j")? {
            Value::Blank => i += 1,
            Value::Real(w) => {
                let components = r.components(i + 1, "Ci")?;
                groups.push((w, components, Vec::new()));
                i += 2;
            }
            Value::Int(_) => {
                let g = r.id(i, "Gi,j")?;
                match groups.last_mut() {
                    Some(group) => group.2.push(g),
                    None => return Err(r.error(i, "WT1", "a weight must precede the grids")),
                }
                i += 1;
            }
            Value::Text(t) if t == "ALPHA" => {
                r.opt_real(i + 1, "ALPHA")?;
                i += 2;
            }
            Value::Text(t) if t == "TREF" => {
                r.opt_real(i + 1, "TREF")?;
                i += 2;
            }
            Value::Text(t) => {
                return Err(r.error(
                    i,
                    "WTi",
                    format!("'{t}' is not supported (UM: the dependent set must be REFGRID/REFC)"),
                ))
            }
        }
    }
    if let Some((w, _, _)) = groups.iter().find(|(_, _, g)| g.is_empty()) {
        return Err(r.card_error(format!("weight {w} has no grids")));
    }
    if groups.is_empty() {
        return Err(r.card_error("no weighted grid groups"));
    }
    Ok(Rbe3 {
        id: r.id(0, "EID")?,
        reference: r.id(2, "REFGRID")?,
        reference_components: r.components(3, "REFC")?,
        groups,
        line: r.card().loc(),
    })
}
