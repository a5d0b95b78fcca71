//! Materials: MAT1 (isotropic), MAT2 (anisotropic plane stress) and MAT8 (orthotropic lamina)
//! for shells.

use nalgebra::Matrix3;

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::Loc;

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

/// MAT2 (anisotropic plane stress) or MAT8 (orthotropic lamina).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ShellMaterialCard {
    Mat2 {
        id: u32,
        /// G11 G12 G13 / G12 G22 G23 / G13 G23 G33.
        g: Matrix3<f64>,
        rho: f64,
        line: Loc,
    },
    Mat8 {
        id: u32,
        e1: f64,
        e2: f64,
        nu12: f64,
        g12: f64,
        g1z: Option<f64>,
        g2z: Option<f64>,
        rho: f64,
        line: Loc,
    },
}

impl ShellMaterialCard {
    pub(crate) fn id(&self) -> u32 {
        match self {
            Self::Mat2 { id, .. } | Self::Mat8 { id, .. } => *id,
        }
    }
}

pub(crate) fn mat2(r: &Reader) -> Result<ShellMaterialCard, FeError> {
    // A1, A2, A3, TREF (thermal), GE (structural damping, added modally by the caller like MAT1
    // GE), ST/SC/SS (allowables), MCSID: accepted, they do not enter K or M.
    r.at_most(17)?;
    for (k, n) in [
        (8, "A1"),
        (9, "A2"),
        (10, "A3"),
        (11, "TREF"),
        (12, "GE"),
        (13, "ST"),
        (14, "SC"),
        (15, "SS"),
    ] {
        r.opt_real(k, n)?;
    }
    r.opt_int(16, "MCSID")?;
    let names = ["G11", "G12", "G13", "G22", "G23", "G33"];
    let mut v = [0.0; 6];
    for (k, n) in names.iter().enumerate() {
        v[k] = r.real_or(1 + k, n, 0.0)?;
    }
    Ok(ShellMaterialCard::Mat2 {
        id: r.id(0, "MID")?,
        g: Matrix3::new(v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5]),
        rho: r.real_or(7, "RHO", 0.0)?,
        line: r.card().loc(),
    })
}

pub(crate) fn mat8(r: &Reader) -> Result<ShellMaterialCard, FeError> {
    // Thermal data, allowables, GE, F12, STRN: accepted, they do not enter K or M.
    r.at_most(19)?;
    for (k, n) in [
        (8, "A1"),
        (9, "A2"),
        (10, "TREF"),
        (11, "Xt"),
        (12, "Xc"),
        (13, "Yt"),
        (14, "Yc"),
        (15, "S"),
        (16, "GE"),
        (17, "F12"),
        (18, "STRN"),
    ] {
        r.opt_real(k, n)?;
    }
    let positive = |k: usize, n: &str, v: f64| {
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(r.error(k, n, format!("must be > 0, got {v}")))
        }
    };
    let optional = |k: usize, n: &str| -> Result<Option<f64>, FeError> {
        match r.opt_real(k, n)? {
            None | Some(0.0) => Ok(None),
            Some(v) => positive(k, n, v).map(Some),
        }
    };
    Ok(ShellMaterialCard::Mat8 {
        id: r.id(0, "MID")?,
        e1: positive(1, "E1", r.real(1, "E1")?)?,
        e2: positive(2, "E2", r.real(2, "E2")?)?,
        nu12: r.real(3, "NU12")?,
        g12: positive(4, "G12", r.real(4, "G12")?)?,
        g1z: optional(5, "G1Z")?,
        g2z: optional(6, "G2Z")?,
        rho: r.real_or(7, "RHO", 0.0)?,
        line: r.card().loc(),
    })
}
