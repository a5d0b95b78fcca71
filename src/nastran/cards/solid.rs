//! Solids: CTETRA (4 or 10 grids), CPENTA (6), CHEXA (8) and their PSOLID.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::{Loc, Value};

/// CTETRA / CPENTA / CHEXA: element id, property and grids in Nastran order.
#[derive(Debug, Clone, PartialEq)]
pub struct SolidElement {
    pub id: u32,
    pub pid: u32,
    pub card: &'static str,
    pub grids: Vec<u32>,
    pub line: Loc,
}

/// PSOLID: material and the options this reader accepts (all others are refused when read).
#[derive(Debug, Clone, PartialEq)]
pub struct Psolid {
    pub id: u32,
    pub mid: u32,
    /// CORDM > 0: a material system, which an isotropic MAT1 makes irrelevant (it must exist).
    pub cordm: Option<u32>,
    pub line: Loc,
}

/// Reads a CTETRA, CPENTA or CHEXA: corner grids required; mid-edge grids all given (CTETRA
/// only) or all blank/0.
pub(crate) fn element(r: &Reader, card: &'static str) -> Result<SolidElement, FeError> {
    let (corners, all) = match card {
        "CTETRA" => (4, 10),
        "CPENTA" => (6, 15),
        _ => (8, 20),
    };
    r.at_most(2 + all)?;
    let mut grids = Vec::with_capacity(all);
    for k in 0..corners {
        grids.push(r.id(2 + k, &format!("G{}", k + 1))?);
    }
    let mut mid = Vec::new();
    for k in corners..all {
        if let Some(g) = r.opt_id_or_zero(2 + k, &format!("G{}", k + 1))? {
            mid.push((k, g));
        }
    }
    match (card, mid.len()) {
        (_, 0) => {}
        ("CTETRA", 6) => grids.extend(mid.iter().map(|&(_, g)| g)),
        ("CTETRA", _) => {
            return Err(r.error(
                2 + mid[0].0,
                &format!("G{}", mid[0].0 + 1),
                format!(
                    "{} of the 6 mid-edge grids given; a CTETRA has all six (10 nodes) or none \
                     (4 nodes)",
                    mid.len()
                ),
            ))
        }
        _ => {
            return Err(r.error(
                2 + mid[0].0,
                &format!("G{}", mid[0].0 + 1),
                format!(
                    "mid-edge grids are not supported: {card} takes {corners} corner grids only"
                ),
            ))
        }
    }
    for (a, g) in grids.iter().enumerate() {
        if grids[..a].contains(g) {
            return Err(r.error(
                2 + a,
                &format!("G{}", a + 1),
                format!("GRID {g} appears twice in the element"),
            ));
        }
    }
    let id = r.id(0, "EID")?;
    Ok(SolidElement {
        id,
        pid: r.opt_id(1, "PID")?.unwrap_or(id),
        card,
        grids,
        line: r.card().loc(),
    })
}

/// Reads a PSOLID. IN blank/0/BUBBLE (the elements' own integration: the hexahedron's
/// incompatible modes play the role of Nastran's bubble functions), STRESS (output location,
/// not used), ISOP blank, FCTN blank/SMECH; anything else changes the element and is refused.
pub(crate) fn psolid(r: &Reader) -> Result<Psolid, FeError> {
    r.at_most(7)?;
    let cordm = match r.opt_int(2, "CORDM")? {
        None | Some(0) | Some(-1) => None,
        Some(c) if c > 0 && c <= u32::MAX as i64 => Some(c as u32),
        Some(c) => return Err(r.error(2, "CORDM", format!("must be >= -1, got {c}"))),
    };
    match r.value(3, "IN")? {
        Value::Blank | Value::Int(0) => {}
        Value::Text(t) if t == "BUBBLE" => {}
        other => {
            return Err(r.error(
                3,
                "IN",
                format!(
                    "{other:?} is not supported: the elements use their own integration (IN \
                     blank, 0 or BUBBLE); TWO/THREE networks are not implemented"
                ),
            ))
        }
    }
    match r.value(4, "STRESS")? {
        Value::Blank | Value::Int(0) | Value::Int(1) => {}
        Value::Text(t) if t == "GRID" || t == "GAUSS" => {}
        other => {
            return Err(r.error(
                4,
                "STRESS",
                format!("{other:?}: expected blank, 0/GRID or 1/GAUSS"),
            ))
        }
    }
    r.require_blank(
        5,
        "ISOP",
        "integration schemes REDUCED/FULL are not implemented (leave ISOP blank)",
    )?;
    match r.value(6, "FCTN")? {
        Value::Blank => {}
        Value::Text(t) if t == "SMECH" => {}
        other => {
            return Err(r.error(
                6,
                "FCTN",
                format!("{other:?} is not supported: only structural solids (SMECH)"),
            ))
        }
    }
    Ok(Psolid {
        id: r.id(0, "PID")?,
        mid: r.id(1, "MID")?,
        cordm,
        line: r.card().loc(),
    })
}
