//! Point masses: CONM2 and CONM1.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::Loc;

/// CONM2: concentrated mass with offset and inertia about its centre of gravity.
#[derive(Debug, Clone, PartialEq)]
pub struct Conm2 {
    pub id: u32,
    pub grid: u32,
    /// -1: X is the centre of gravity in basic; 0/blank: offset in basic; > 0: offset in CORD2R.
    pub cid: i64,
    pub mass: f64,
    pub x: [f64; 3],
    /// I11, I21, I22, I31, I32, I33 as entered.
    pub inertia: [f64; 6],
    pub line: Loc,
}

pub(crate) fn conm2(r: &Reader) -> Result<Conm2, FeError> {
    r.at_most(14)?;
    r.require_blank(7, "blank", "field 9 of CONM2 is unused")?;
    let cid = r.int_or(2, "CID", 0)?;
    if cid < -1 {
        return Err(r.error(2, "CID", format!("must be >= -1, got {cid}")));
    }
    let names = ["I11", "I21", "I22", "I31", "I32", "I33"];
    let mut inertia = [0.0; 6];
    for (k, n) in names.iter().enumerate() {
        inertia[k] = r.real_or(8 + k, n, 0.0)?;
    }
    Ok(Conm2 {
        id: r.id(0, "EID")?,
        grid: r.id(1, "G")?,
        cid,
        mass: r.real(3, "M")?,
        x: [
            r.real_or(4, "X1", 0.0)?,
            r.real_or(5, "X2", 0.0)?,
            r.real_or(6, "X3", 0.0)?,
        ],
        inertia,
        line: r.card().loc(),
    })
}

/// CONM1: 6 × 6 mass matrix at a grid, in the grid's system or a CORD2R.
#[derive(Debug, Clone, PartialEq)]
pub struct Conm1 {
    pub id: u32,
    pub grid: u32,
    /// 0/blank: basic; > 0: a CORD2R.
    pub cid: Option<u32>,
    /// The symmetric matrix (ux uy uz rx ry rz), from the lower triangle as entered.
    pub matrix: [[f64; 6]; 6],
    pub line: Loc,
}

pub(crate) fn conm1(r: &Reader) -> Result<Conm1, FeError> {
    r.at_most(24)?;
    let mut matrix = [[0.0; 6]; 6];
    // Lower triangle by rows: M11, M21, M22, M31, … from field index 3 on.
    let entries = (0..6).flat_map(|i| (0..=i).map(move |j| (i, j)));
    for (k, (i, j)) in entries.enumerate() {
        let v = r.real_or(3 + k, &format!("M{}{}", i + 1, j + 1), 0.0)?;
        matrix[i][j] = v;
        matrix[j][i] = v;
    }
    Ok(Conm1 {
        id: r.id(0, "EID")?,
        grid: r.id(1, "G")?,
        cid: r.opt_id_or_zero(2, "CID")?,
        matrix,
        line: r.card().loc(),
    })
}
