//! Shells: PSHELL and the CQUAD4 / CTRIA3 elements.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::{Loc, Value};

/// PSHELL: homogeneous shell property.
#[derive(Debug, Clone, PartialEq)]
pub struct Pshell {
    pub id: u32,
    pub mid1: Option<u32>,
    pub t: f64,
    pub mid2: Option<i64>,
    pub bending_ratio: f64,
    pub mid3: Option<u32>,
    pub ts_t: f64,
    pub nsm: f64,
    pub line: Loc,
}

pub(crate) fn pshell(r: &Reader) -> Result<Pshell, FeError> {
    r.at_most(11)?;
    r.opt_real(8, "Z1")?;
    r.opt_real(9, "Z2")?;
    r.require_blank(10, "MID4", "membrane-bending coupling is not supported")?;
    Ok(Pshell {
        id: r.id(0, "PID")?,
        mid1: r.opt_id(1, "MID1")?,
        t: r.real(2, "T")?,
        mid2: r.opt_int(3, "MID2")?,
        bending_ratio: r.real_or(4, "12I/T**3", 1.0)?,
        mid3: r.opt_id(5, "MID3")?,
        ts_t: r.real_or(6, "TS/T", 0.833333)?,
        nsm: r.real_or(7, "NSM", 0.0)?,
        line: r.card().loc(),
    })
}

/// CQUAD4 / CTRIA3.
#[derive(Debug, Clone, PartialEq)]
pub struct Plate {
    pub id: u32,
    pub pid: u32,
    pub grids: Vec<u32>,
    /// THETA (degrees from the side G1 → G2), 0 when blank or when MCID is given.
    pub theta: f64,
    /// MCID when the THETA/MCID field holds an integer.
    pub mcid: Option<i64>,
    pub zoffs: f64,
    pub line: Loc,
}

pub(crate) fn plate(r: &Reader, corners: usize) -> Result<Plate, FeError> {
    let id = r.id(0, "EID")?;
    let grids = (0..corners)
        .map(|k| r.id(2 + k, &format!("G{}", k + 1)))
        .collect::<Result<Vec<_>, _>>()?;
    let (theta, mcid) = match r.value(2 + corners, "THETA/MCID")? {
        Value::Blank => (0.0, None),
        Value::Real(v) => (v, None),
        Value::Int(v) if v >= 0 => (0.0, Some(v)),
        other => {
            return Err(r.error(
                2 + corners,
                "THETA/MCID",
                format!("expected THETA (real) or MCID (integer >= 0), found {other:?}"),
            ))
        }
    };
    let zoffs = r.real_or(3 + corners, "ZOFFS", 0.0)?;
    let why = "corner thicknesses are not supported; give T on the PSHELL";
    let tflag = if corners == 4 { 9 } else { 10 };
    r.require_blank(tflag, "TFLAG", why)?;
    for k in 0..corners {
        r.require_blank(tflag + 1 + k, &format!("T{}", k + 1), why)?;
    }
    r.at_most(tflag + 1 + corners)?;
    Ok(Plate {
        id,
        pid: r.opt_id(1, "PID")?.unwrap_or(id),
        grids,
        theta,
        mcid,
        zoffs,
        line: r.card().loc(),
    })
}
