//! Beams: PBAR, PBEAM and the CBAR / CBEAM elements.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::{Loc, Value};

/// PBAR / PBEAM reduced to a constant prismatic section.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamProperty {
    pub id: u32,
    pub mid: u32,
    pub a: f64,
    pub i1: f64,
    pub i2: f64,
    pub j: f64,
    pub nsm: f64,
    /// Shear area factors K1 (plane 1) and K2 (plane 2); `None` is rigid in shear.
    pub k: [Option<f64>; 2],
    pub line: Loc,
}

/// A shear area factor: `blank` is what a blank field means (PBAR: rigid, PBEAM: 1.0); 0.0 is
/// rigid in shear on both cards; negative is refused.
fn shear_factor(
    r: &Reader,
    i: usize,
    name: &str,
    blank: Option<f64>,
) -> Result<Option<f64>, FeError> {
    match r.opt_real(i, name)? {
        None => Ok(blank),
        Some(0.0) => Ok(None),
        Some(k) if k > 0.0 => Ok(Some(k)),
        Some(k) => Err(r.error(i, name, format!("{k}: a shear area factor must be >= 0"))),
    }
}

pub(crate) fn pbar(r: &Reader) -> Result<BeamProperty, FeError> {
    r.at_most(19)?;
    r.require_blank(7, "blank", "field 9 of PBAR is unused")?;
    for (k, n) in [
        (8, "C1"),
        (9, "C2"),
        (10, "D1"),
        (11, "D2"),
        (12, "E1"),
        (13, "E2"),
        (14, "F1"),
        (15, "F2"),
    ] {
        // Stress recovery points: no part of K or M.
        r.opt_real(k, n)?;
    }
    r.require_blank(18, "I12", "unsymmetric sections are not supported")?;
    Ok(BeamProperty {
        id: r.id(0, "PID")?,
        mid: r.id(1, "MID")?,
        a: r.real(2, "A")?,
        i1: r.real_or(3, "I1", 0.0)?,
        i2: r.real_or(4, "I2", 0.0)?,
        j: r.real_or(5, "J", 0.0)?,
        nsm: r.real_or(6, "NSM", 0.0)?,
        // Blank or 0.0: infinite K, shear flexibility neglected (the MSC/Autodesk PBAR remark).
        k: [
            shear_factor(r, 16, "K1", None)?,
            shear_factor(r, 17, "K2", None)?,
        ],
        line: r.card().loc(),
    })
}

/// PBEAM: a constant section, read from end A; intermediate stations and end B must repeat it.
///
/// Long on purpose: the card's fields in the order Nastran lays them out (end A, then a variable
/// number of stations whose length depends on SO, then the shear factors and the refused
/// features); each check names its field, so the reading follows the card line by line.
pub(crate) fn pbeam(r: &Reader) -> Result<BeamProperty, FeError> {
    let end_a = BeamProperty {
        id: r.id(0, "PID")?,
        mid: r.id(1, "MID")?,
        a: r.real(2, "A(A)")?,
        i1: r.real_or(3, "I1(A)", 0.0)?,
        i2: r.real_or(4, "I2(A)", 0.0)?,
        j: r.real_or(6, "J(A)", 0.0)?,
        nsm: r.real_or(7, "NSM(A)", 0.0)?,
        k: [None, None],
        line: r.card().loc(),
    };
    r.require_blank(5, "I12(A)", "unsymmetric sections are not supported")?;
    for k in 8..16 {
        r.opt_real(k, "stress recovery point")?;
    }
    // Intermediate stations and end B: SO, X/XB, A, I1, I2, I12, J, NSM [, C1 … F2 if SO = YES].
    let mut i = 16;
    while let Value::Text(so) = r.value(i, "SO")? {
        if !matches!(so.as_str(), "YES" | "YESA" | "NO") {
            return Err(r.error(i, "SO", format!("expected YES, YESA or NO, found {so}")));
        }
        r.real(i + 1, "X/XB")?;
        let same = [
            (2, "A", end_a.a),
            (3, "I1", end_a.i1),
            (4, "I2", end_a.i2),
            (5, "I12", 0.0),
            (6, "J", end_a.j),
            (7, "NSM", end_a.nsm),
        ];
        for (k, name, at_a) in same {
            if let Some(v) = r.opt_real(i + k, name)? {
                if (v - at_a).abs() > 1e-9 * at_a.abs().max(f64::MIN_POSITIVE) {
                    return Err(r.error(
                        i + k,
                        name,
                        format!(
                            "{v} differs from end A ({at_a}): tapered PBEAM sections are not \
                             supported"
                        ),
                    ));
                }
            }
        }
        if so == "YES" {
            for k in 8..16 {
                r.opt_real(i + k, "stress recovery point")?;
            }
            i += 16;
        } else {
            i += 8;
        }
    }
    // K1 K2 (shear area factors: blank 1.0, 0.0 rigid in shear, the MSC PBEAM remark), S1 S2
    // (shear relief for tapered beams: irrelevant for a constant section), then features that
    // change K or M.
    let k = [
        shear_factor(r, i, "K1", Some(1.0))?,
        shear_factor(r, i + 1, "K2", Some(1.0))?,
    ];
    for (k, name) in [(2, "S1"), (3, "S2")] {
        r.opt_real(i + k, name)?;
    }
    let why = "non-structural mass inertia, warping and offsets of the centre of gravity or \
               neutral axis are not supported";
    for (k, name) in [
        (4, "NSI(A)"),
        (5, "NSI(B)"),
        (6, "CW(A)"),
        (7, "CW(B)"),
        (8, "M1(A)"),
        (9, "M2(A)"),
        (10, "M1(B)"),
        (11, "M2(B)"),
        (12, "N1(A)"),
        (13, "N2(A)"),
        (14, "N1(B)"),
        (15, "N2(B)"),
    ] {
        r.require_blank(i + k, name, why)?;
    }
    r.at_most(i + 16)?;
    Ok(BeamProperty { k, ..end_a })
}

/// How a bar's element y axis is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    /// Vector X1, X2, X3 (in the system OFFT's first letter names for CBAR/CBEAM).
    Vector([f64; 3]),
    /// Direction from end A to grid G0.
    Node(u32),
}

/// Where a CBAR/CBEAM vector is measured (a letter of OFFT).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VectorSystem {
    /// G: the displacement coordinate system (GRID CD) of the grid the vector starts at.
    Grid,
    /// B: basic.
    Basic,
    /// O: the offset system (x from GA to GB, y in the plane of x and the orientation vector).
    Element,
}

/// CBAR / CBEAM.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    pub id: u32,
    pub pid: u32,
    pub ga: u32,
    pub gb: u32,
    pub orientation: Orientation,
    /// OFFT: system of the orientation vector, of offset A, of offset B.
    pub offt: [VectorSystem; 3],
    /// PA, PB: released DOFs (element axes) at end A, end B.
    pub pins: [[bool; 6]; 2],
    /// W1A..W3A, W1B..W3B.
    pub offsets: [[f64; 3]; 2],
    pub line: Loc,
}

/// OFFT: three letters, orientation vector G or B, each offset G or O (Nastran's table: GGG,
/// BGG, GGO, BGO, GOG, BOG, GOO, BOO); blank is GGG.
fn offt(r: &Reader) -> Result<[VectorSystem; 3], FeError> {
    let code = match r.value(7, "OFFT")? {
        Value::Blank => return Ok([VectorSystem::Grid; 3]),
        Value::Text(t) => t,
        other => {
            return Err(r.error(
                7,
                "OFFT",
                format!("{other:?} is not an offset code (GGG, BGG, GGO, BGO, GOG, BOG, GOO, BOO)"),
            ))
        }
    };
    let letters: Vec<char> = code.chars().collect();
    let parsed = match letters[..] {
        [v, a, b] => [(v, true), (a, false), (b, false)].map(|(c, vector)| match (c, vector) {
            ('G', _) => Some(VectorSystem::Grid),
            ('B', true) => Some(VectorSystem::Basic),
            ('O', false) => Some(VectorSystem::Element),
            _ => None,
        }),
        _ => [None; 3],
    };
    match parsed {
        [Some(v), Some(a), Some(b)] => Ok([v, a, b]),
        _ => Err(r.error(
            7,
            "OFFT",
            format!(
                "'{code}' is not an offset code: the orientation vector is G or B, each offset G \
                 or O (GGG, BGG, GGO, BGO, GOG, BOG, GOO, BOO)"
            ),
        )),
    }
}

/// PA / PB: up to five distinct digits 1..6; blank or 0 releases nothing.
fn pin_flags(r: &Reader, i: usize, name: &str) -> Result<[bool; 6], FeError> {
    match r.opt_int(i, name)? {
        None | Some(0) => Ok([false; 6]),
        Some(_) => {
            let mask = r.components(i, name)?;
            if mask.iter().all(|&m| m) {
                return Err(r.error(
                    i,
                    name,
                    "releases all six DOFs of the end, which would leave the grid unconnected: \
                     Nastran allows up to five pin flags per end",
                ));
            }
            Ok(mask)
        }
    }
}

pub(crate) fn bar(r: &Reader, is_beam: bool) -> Result<Bar, FeError> {
    r.at_most(if is_beam { 18 } else { 16 })?;
    let id = r.id(0, "EID")?;
    let orientation =
        match r.value(4, "X1/G0")? {
            Value::Int(_) => {
                r.require_blank(5, "X2", "with G0 given, X2 must be blank")?;
                r.require_blank(6, "X3", "with G0 given, X3 must be blank")?;
                Orientation::Node(r.id(4, "G0")?)
            }
            Value::Real(x1) => {
                Orientation::Vector([x1, r.real_or(5, "X2", 0.0)?, r.real_or(6, "X3", 0.0)?])
            }
            _ => return Err(r.error(
                4,
                "X1/G0",
                "an orientation vector or G0 is required (BAROR/BEAMOR defaults are not supported)",
            )),
        };
    let offt = offt(r)?;
    let pins = [pin_flags(r, 8, "PA")?, pin_flags(r, 9, "PB")?];
    let names = [["W1A", "W2A", "W3A"], ["W1B", "W2B", "W3B"]];
    let mut offsets = [[0.0; 3]; 2];
    for (end, w) in offsets.iter_mut().enumerate() {
        for (d, v) in w.iter_mut().enumerate() {
            *v = r.real_or(10 + 3 * end + d, names[end][d], 0.0)?;
        }
    }
    if is_beam {
        r.require_blank(16, "SA", "warping scalar points are not supported")?;
        r.require_blank(17, "SB", "warping scalar points are not supported")?;
    }
    Ok(Bar {
        id,
        pid: r.opt_id(1, "PID")?.unwrap_or(id),
        ga: r.id(2, "GA")?,
        gb: r.id(3, "GB")?,
        orientation,
        offt,
        pins,
        offsets,
        line: r.card().loc(),
    })
}
