//! Bushes: CBUSH and PBUSH.

use super::beam::Orientation;
use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::{Loc, Value};

/// How a CBUSH's element axes are given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BushAxes {
    /// CID: 0 basic, > 0 a CORD2R.
    System(u32),
    /// CID blank: x from GA to GB, y in the plane of x and this vector (or basic if GA and GB
    /// coincide or GB is blank).
    Line(Option<Orientation>),
}

/// CBUSH: generalised spring-damper.
#[derive(Debug, Clone, PartialEq)]
pub struct Cbush {
    pub id: u32,
    pub pid: u32,
    pub ga: u32,
    pub gb: Option<u32>,
    pub axes: BushAxes,
    /// Spring location along GA → GB (0 at GA).
    pub s: f64,
    pub line: Loc,
}

pub(crate) fn cbush(r: &Reader) -> Result<Cbush, FeError> {
    r.at_most(13)?;
    let id = r.id(0, "EID")?;
    let orientation = match r.value(4, "GO/X1")? {
        Value::Blank => {
            r.require_blank(5, "X2", "X2 without X1")?;
            r.require_blank(6, "X3", "X3 without X1")?;
            None
        }
        Value::Int(_) => {
            r.require_blank(5, "X2", "with GO given, X2 must be blank")?;
            r.require_blank(6, "X3", "with GO given, X3 must be blank")?;
            Some(Orientation::Node(r.id(4, "GO")?))
        }
        Value::Real(x1) => Some(Orientation::Vector([
            x1,
            r.real_or(5, "X2", 0.0)?,
            r.real_or(6, "X3", 0.0)?,
        ])),
        Value::Text(t) => return Err(r.error(4, "GO/X1", format!("unexpected '{t}'"))),
    };
    let axes = match r.opt_int(7, "CID")? {
        None => BushAxes::Line(orientation),
        Some(c) if (0..=u32::MAX as i64).contains(&c) => BushAxes::System(c as u32),
        Some(c) => return Err(r.error(7, "CID", format!("must be blank or >= 0, got {c}"))),
    };
    let s = r.real_or(8, "S", 0.5)?;
    if !(0.0..=1.0).contains(&s) {
        return Err(r.error(8, "S", format!("must lie in [0, 1], got {s}")));
    }
    match r.opt_int(9, "OCID")? {
        None | Some(-1) => {}
        Some(o) => {
            return Err(r.error(
                9,
                "OCID",
                format!(
                    "{o} is not supported: the spring point lies on the line GA-GB (OCID -1/blank)"
                ),
            ))
        }
    }
    let why = "offsets S1..S3 in OCID are not supported (OCID must be -1/blank)";
    for (k, n) in [(10, "S1"), (11, "S2"), (12, "S3")] {
        r.require_blank(k, n, why)?;
    }
    Ok(Cbush {
        id,
        pid: r.opt_id(1, "PID")?.unwrap_or(id),
        ga: r.id(2, "GA")?,
        gb: r.opt_id_or_zero(3, "GB")?,
        axes,
        s,
        line: r.card().loc(),
    })
}

/// PBUSH: stiffness K1..K6 and viscous damping B1..B6 of a CBUSH.
#[derive(Debug, Clone, PartialEq)]
pub struct Pbush {
    pub id: u32,
    pub k: [f64; 6],
    pub b: [f64; 6],
    pub line: Loc,
}

pub(crate) fn pbush(r: &Reader) -> Result<Pbush, FeError> {
    let mut out = Pbush {
        id: r.id(0, "PID")?,
        k: [0.0; 6],
        b: [0.0; 6],
        line: r.card().loc(),
    };
    // Lines of a keyword (field 3) and up to six values; field 2 of a continuation is blank.
    let mut base = 0;
    while base < r.len() {
        if base > 0 {
            r.require_blank(base, "blank", "field 2 of a PBUSH continuation is unused")?;
        }
        let values = |target: &mut [f64; 6], name: &str| -> Result<(), FeError> {
            for (d, v) in target.iter_mut().enumerate() {
                *v = r.real_or(base + 2 + d, &format!("{name}{}", d + 1), 0.0)?;
            }
            Ok(())
        };
        match r.value(base + 1, "keyword")? {
            Value::Text(t) if t == "K" => values(&mut out.k, "K")?,
            Value::Text(t) if t == "B" => values(&mut out.b, "B")?,
            Value::Text(t) if t == "GE" => {
                for d in 0..6 {
                    r.require_blank(
                        base + 2 + d,
                        &format!("GE{}", d + 1),
                        "structural damping of a bush is not supported (give viscous B, or add \
                         structural damping modally)",
                    )?;
                }
            }
            Value::Text(t) if t == "RCV" => {
                // Stress and strain recovery coefficients: output only.
                for d in 0..4 {
                    r.opt_real(base + 2 + d, "SA/ST/EA/ET")?;
                }
                r.require_blank(base + 6, "blank", "RCV has four values")?;
                r.require_blank(base + 7, "blank", "RCV has four values")?;
            }
            Value::Blank => {
                for d in 0..6 {
                    r.require_blank(base + 2 + d, "value", "a value without a keyword")?;
                }
            }
            other => {
                return Err(r.error(
                    base + 1,
                    "keyword",
                    format!("{other:?} is not supported (supported: K, B; GE blank; RCV)"),
                ))
            }
        }
        base += 8;
    }
    Ok(out)
}
