//! GRID and the coordinate systems CORD2R, CORD2C, CORD2S.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::Loc;

/// GRID: a node.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub id: u32,
    pub cp: Option<u32>,
    pub x: [f64; 3],
    /// Displacement coordinate system (blank/0: basic).
    pub cd: Option<u32>,
    pub ps: [bool; 6],
    pub line: Loc,
}

pub(crate) fn grid(r: &Reader) -> Result<Grid, FeError> {
    r.at_most(8)?;
    r.require_blank(7, "SEID", "superelements are not supported")?;
    let ps = if r.opt_int(6, "PS")?.is_some() {
        r.components(6, "PS")?
    } else {
        [false; 6]
    };
    Ok(Grid {
        id: r.id(0, "ID")?,
        cp: r.opt_id_or_zero(1, "CP")?,
        x: [
            r.real_or(2, "X1", 0.0)?,
            r.real_or(3, "X2", 0.0)?,
            r.real_or(4, "X3", 0.0)?,
        ],
        cd: r.opt_id_or_zero(5, "CD")?,
        ps,
        line: r.card().loc(),
    })
}

/// Kind of a coordinate system defined by three points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SystemKind {
    /// CORD2R: x1, x2, x3 Cartesian.
    Rectangular,
    /// CORD2C: r, θ (degrees, from x about z), z.
    Cylindrical,
    /// CORD2S: r, θ (degrees, from z), φ (degrees, from x about z).
    Spherical,
}

impl SystemKind {
    /// The card that defines this kind.
    pub fn card(self) -> &'static str {
        match self {
            SystemKind::Rectangular => "CORD2R",
            SystemKind::Cylindrical => "CORD2C",
            SystemKind::Spherical => "CORD2S",
        }
    }
}

/// CORD2R / CORD2C / CORD2S: a system by three points (A origin, B on z, C in the x-z plane)
/// given in the system RID.
#[derive(Debug, Clone, PartialEq)]
pub struct Cord2r {
    pub kind: SystemKind,
    pub id: u32,
    pub rid: Option<u32>,
    pub a: [f64; 3],
    pub b: [f64; 3],
    pub c: [f64; 3],
    pub line: Loc,
}

pub(crate) fn cord2(r: &Reader, kind: SystemKind) -> Result<Cord2r, FeError> {
    r.at_most(11)?;
    let p = |k: usize, n: &str| -> Result<[f64; 3], FeError> {
        Ok([
            r.real_or(k, &format!("{n}1"), 0.0)?,
            r.real_or(k + 1, &format!("{n}2"), 0.0)?,
            r.real_or(k + 2, &format!("{n}3"), 0.0)?,
        ])
    };
    Ok(Cord2r {
        kind,
        id: r.id(0, "CID")?,
        rid: r.opt_id_or_zero(1, "RID")?,
        a: p(2, "A")?,
        b: p(5, "B")?,
        c: p(8, "C")?,
        line: r.card().loc(),
    })
}
