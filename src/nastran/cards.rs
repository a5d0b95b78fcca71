//! Typed bulk data cards: each supported card's fields read by position with Nastran's types
//! and defaults; every malformed field is an error naming the line, field number and meaning.

use super::lexer::{classify, Loc, RawCard, Value};
use crate::fe::error::FeError;

/// Typed access to the fields of one card.
pub(crate) struct Reader<'a> {
    card: &'a RawCard,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(card: &'a RawCard) -> Self {
        Self { card }
    }

    pub(crate) fn card(&self) -> &RawCard {
        self.card
    }

    /// Where data field `i` is (or would be): line and Nastran field number.
    fn place(&self, i: usize) -> (Loc, usize) {
        match self.card.fields.get(i) {
            Some(f) => (self.card.loc_of_line(f.line), f.position),
            None => (self.card.loc(), i % 8 + 2),
        }
    }

    /// Where data field `i` is (its line).
    pub(crate) fn field_loc(&self, i: usize) -> Loc {
        self.place(i).0
    }

    pub(crate) fn error(&self, i: usize, name: &str, message: impl std::fmt::Display) -> FeError {
        let (line, position) = self.place(i);
        FeError::InvalidInput(format!(
            "Nastran bulk data line {line}: {} (card at line {}) field {position} ({name}): \
             {message}",
            self.card.name,
            self.card.loc()
        ))
    }

    /// A whole-card error at the card's first line.
    pub(crate) fn card_error(&self, message: impl std::fmt::Display) -> FeError {
        FeError::InvalidInput(format!(
            "Nastran bulk data line {}: {}: {message}",
            self.card.loc(),
            self.card.name
        ))
    }

    pub(crate) fn len(&self) -> usize {
        self.card.fields.len()
    }

    pub(crate) fn value(&self, i: usize, name: &str) -> Result<Value, FeError> {
        match self.card.fields.get(i) {
            None => Ok(Value::Blank),
            Some(f) => classify(&f.text).map_err(|m| self.error(i, name, m)),
        }
    }

    pub(crate) fn opt_int(&self, i: usize, name: &str) -> Result<Option<i64>, FeError> {
        match self.value(i, name)? {
            Value::Blank => Ok(None),
            Value::Int(v) => Ok(Some(v)),
            other => Err(self.error(i, name, format!("expected an integer, found {other:?}"))),
        }
    }

    pub(crate) fn int_or(&self, i: usize, name: &str, default: i64) -> Result<i64, FeError> {
        Ok(self.opt_int(i, name)?.unwrap_or(default))
    }

    /// A positive identification number (required).
    pub(crate) fn id(&self, i: usize, name: &str) -> Result<u32, FeError> {
        match self.opt_id(i, name)? {
            Some(v) => Ok(v),
            None => Err(self.error(i, name, "is required")),
        }
    }

    /// A positive identification number or blank.
    pub(crate) fn opt_id(&self, i: usize, name: &str) -> Result<Option<u32>, FeError> {
        match self.opt_int(i, name)? {
            None => Ok(None),
            Some(v) if v > 0 && v <= u32::MAX as i64 => Ok(Some(v as u32)),
            Some(v) => Err(self.error(i, name, format!("must be a positive id, got {v}"))),
        }
    }

    /// An id where blank and 0 both mean "none" (coordinate systems, optional grids).
    pub(crate) fn opt_id_or_zero(&self, i: usize, name: &str) -> Result<Option<u32>, FeError> {
        match self.opt_int(i, name)? {
            None | Some(0) => Ok(None),
            Some(v) if v > 0 && v <= u32::MAX as i64 => Ok(Some(v as u32)),
            Some(v) => Err(self.error(i, name, format!("must be >= 0, got {v}"))),
        }
    }

    pub(crate) fn opt_real(&self, i: usize, name: &str) -> Result<Option<f64>, FeError> {
        match self.value(i, name)? {
            Value::Blank => Ok(None),
            Value::Real(v) => Ok(Some(v)),
            Value::Int(v) => Err(self.error(
                i,
                name,
                format!("expected a real, found integer {v} (Nastran reals need a decimal point)"),
            )),
            other => Err(self.error(i, name, format!("expected a real, found {other:?}"))),
        }
    }

    pub(crate) fn real(&self, i: usize, name: &str) -> Result<f64, FeError> {
        self.opt_real(i, name)?
            .ok_or_else(|| self.error(i, name, "is required"))
    }

    pub(crate) fn real_or(&self, i: usize, name: &str, default: f64) -> Result<f64, FeError> {
        Ok(self.opt_real(i, name)?.unwrap_or(default))
    }

    /// Component digits 1..6 ("123456", no repeats) as a DOF mask (required, non-empty).
    pub(crate) fn components(&self, i: usize, name: &str) -> Result<[bool; 6], FeError> {
        let Some(v) = self.opt_int(i, name)? else {
            return Err(self.error(i, name, "component digits 1..6 are required"));
        };
        let text = v.to_string();
        let mut mask = [false; 6];
        for c in text.chars() {
            match c.to_digit(10) {
                Some(d @ 1..=6) if !mask[d as usize - 1] => mask[d as usize - 1] = true,
                _ => {
                    return Err(self.error(
                        i,
                        name,
                        format!("'{text}' is not a set of distinct component digits 1..6"),
                    ))
                }
            }
        }
        Ok(mask)
    }

    /// A single scalar-element component 1..6 (0/blank would be a scalar point: not supported).
    pub(crate) fn component(&self, i: usize, name: &str) -> Result<usize, FeError> {
        match self.opt_int(i, name)? {
            Some(c @ 1..=6) => Ok(c as usize - 1),
            other => Err(self.error(
                i,
                name,
                format!(
                    "expected one component 1..6, found {other:?} (scalar points are not supported)"
                ),
            )),
        }
    }

    /// Field `i` must be blank (or a zero of either type): features this reader does not model.
    pub(crate) fn require_blank(&self, i: usize, name: &str, why: &str) -> Result<(), FeError> {
        match self.value(i, name)? {
            Value::Blank => Ok(()),
            Value::Int(0) | Value::Real(0.0) => Ok(()),
            other => Err(self.error(i, name, format!("{other:?} is not supported: {why}"))),
        }
    }

    /// No data beyond field index `n - 1`.
    pub(crate) fn at_most(&self, n: usize) -> Result<(), FeError> {
        match self
            .card
            .fields
            .iter()
            .enumerate()
            .skip(n)
            .find(|(_, f)| !f.text.is_empty())
        {
            Some((i, f)) => Err(self.error(
                i,
                "beyond the card's last field",
                format!("unexpected data '{}'", f.text),
            )),
            None => Ok(()),
        }
    }
}

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

/// MAT1: isotropic material; missing E, G or NU follow Nastran's rule in `to_mesh`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mat1 {
    pub id: u32,
    pub e: Option<f64>,
    pub g: Option<f64>,
    pub nu: Option<f64>,
    pub rho: f64,
    pub line: Loc,
}

pub(crate) fn mat1(r: &Reader) -> Result<Mat1, FeError> {
    // A, TREF (thermal), GE (structural damping: added modally by the caller), ST/SC/SS
    // (allowables), MCSID are accepted and do not enter K or M.
    r.at_most(12)?;
    for (k, n) in [
        (5, "A"),
        (6, "TREF"),
        (7, "GE"),
        (8, "ST"),
        (9, "SC"),
        (10, "SS"),
    ] {
        r.opt_real(k, n)?;
    }
    r.opt_int(11, "MCSID")?;
    Ok(Mat1 {
        id: r.id(0, "MID")?,
        e: r.opt_real(1, "E")?,
        g: r.opt_real(2, "G")?,
        nu: r.opt_real(3, "NU")?,
        rho: r.real_or(4, "RHO", 0.0)?,
        line: r.card().loc(),
    })
}

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

/// A `TABDMP1` as read: modal damping against natural frequency, its values in the card's unit
/// (the reduction turns the table the case control's `SDAMPING` names into the body's damping).
#[derive(Debug, Clone, PartialEq)]
pub struct DampingTableCard {
    /// Table id (TID).
    pub id: u32,
    /// TYPE: `G` (blank, Nastran's default), `CRIT` or `Q`.
    pub kind: &'static str,
    /// (frequency in cycles per unit time, value) pairs in the order given, `SKIP` pairs left
    /// out.
    pub points: Vec<[f64; 2]>,
    /// Where each point's frequency field is, for messages.
    pub point_lines: Vec<Loc>,
    /// Where the card starts.
    pub loc: Loc,
}

/// `TABDMP1 TID TYPE` (fields 4–9 blank, or OptiStruct's `FLAT = 1` in field 4), then pairs
/// `f1 g1 f2 g2 …` on the continuations up to `ENDT`; a pair with `SKIP` in either field is
/// left out. Outside the table the end values are held (`FLAT = 1`); the linear extrapolation
/// of MSC Nastran (`FLAT = 0` in OptiStruct) is refused when asked for explicitly.
pub(crate) fn tabdmp1(r: &Reader) -> Result<DampingTableCard, FeError> {
    let id = r.id(0, "TID")?;
    let kind = match r.value(1, "TYPE")? {
        Value::Blank => "G",
        Value::Text(t) if t == "G" => "G",
        Value::Text(t) if t == "CRIT" => "CRIT",
        Value::Text(t) if t == "Q" => "Q",
        other => {
            let shown = match other {
                Value::Text(t) => t,
                Value::Int(v) => v.to_string(),
                Value::Real(v) => v.to_string(),
                Value::Blank => String::new(),
            };
            return Err(r.error(
                1,
                "TYPE",
                format!("TABDMP1 {id}: damping type '{shown}' is not handled (G, CRIT or Q)"),
            ));
        }
    };
    match r.opt_int(2, "FLAT")? {
        None | Some(1) => {}
        Some(0) => {
            return Err(r.error(
                2,
                "FLAT",
                format!(
                    "TABDMP1 {id}: FLAT = 0 (linear extrapolation beyond the table) is not \
                     handled: the end values are held (FLAT = 1)"
                ),
            ))
        }
        Some(v) => return Err(r.error(2, "FLAT", format!("must be 0 or 1, got {v}"))),
    }
    for i in 3..8 {
        if !matches!(r.value(i, "blank")?, Value::Blank) {
            return Err(r.error(i, "blank", format!("TABDMP1 {id}: the field must be blank")));
        }
    }
    let is = |v: &Value, word: &str| matches!(v, Value::Text(t) if t == word);
    let (mut points, mut point_lines) = (Vec::new(), Vec::new());
    let mut i = 8;
    loop {
        let (f, g) = (r.value(i, "fi")?, r.value(i + 1, "gi")?);
        if is(&f, "ENDT") || is(&g, "ENDT") {
            let after = if is(&f, "ENDT") { i + 1 } else { i + 2 };
            return match (after..r.len())
                .find(|&j| !matches!(r.value(j, "").ok(), Some(Value::Blank)))
            {
                Some(j) => Err(r.error(
                    j,
                    "after ENDT",
                    format!("TABDMP1 {id}: data after the end of the table (ENDT)"),
                )),
                None if points.is_empty() => Err(r.card_error(format!(
                    "TABDMP1 {id}: the table has no point (at least one frequency and value \
                     before ENDT)"
                ))),
                None => Ok(DampingTableCard {
                    id,
                    kind,
                    points,
                    point_lines,
                    loc: r.card().loc(),
                }),
            };
        }
        if i >= r.len() {
            return Err(r.card_error(format!("TABDMP1 {id}: no ENDT ends the table")));
        }
        if !(is(&f, "SKIP") || is(&g, "SKIP")) {
            points.push([r.real(i, "fi")?, r.real(i + 1, "gi")?]);
            point_lines.push(r.field_loc(i));
        }
        i += 2;
    }
}
