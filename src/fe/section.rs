//! Materials and the cross-section data of shells (membrane, bending and transverse shear
//! stiffness, material orientation and offset: Nastran PSHELL with MAT1/MAT2/MAT8). Data of the
//! mesh, used by the elements ([`super::shell`], [`super::shell3`], [`super::beam`],
//! [`super::solid`]) and by the deck reader; a leaf that imports no other part of the mesh.

use nalgebra::{Matrix2, Matrix3};
use serde::{Deserialize, Serialize};

use super::error::FeError;

/// Linear elastic isotropic material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Young's modulus (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio (-).
    pub poisson_ratio: f64,
    /// Density (kg/m³).
    pub density: f64,
}

impl Material {
    /// Structural steel.
    pub const STEEL: Material = Material {
        youngs_modulus: 210.0e9,
        poisson_ratio: 0.3,
        density: 7850.0,
    };

    /// Shear modulus G = E / (2 (1 + ν)).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

/// Shear correction factor of the Mindlin plate.
pub(crate) const SHEAR_CORRECTION: f64 = 5.0 / 6.0;

/// Stiffness of a general shell section: separate membrane, bending and transverse shear
/// constitutive matrices in material axes (orthotropic or anisotropic sheets, Nastran PSHELL with
/// MAT1/MAT2/MAT8 and different MID1/MID2/MID3), a material orientation and an offset reference
/// plane. A shell without a section is the homogeneous isotropic sheet of its `material`.
///
/// Strains in material axes (1, 2): membrane (ε₁, ε₂, γ₁₂), curvatures (κ₁, κ₂, κ₁₂),
/// transverse shear (γ₁z, γ₂z). Mass still comes from the shell's density, thickness,
/// bending thickness (rotary inertia) and non-structural mass.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellSection {
    /// A (N/m): (N₁, N₂, N₁₂) = A (ε₁, ε₂, γ₁₂) on the reference plane.
    pub membrane: Matrix3<f64>,
    /// D (N·m): (M₁, M₂, M₁₂) = D (κ₁, κ₂, κ₁₂).
    pub bending: Matrix3<f64>,
    /// S (N/m): (Q₁, Q₂) = S (γ₁z, γ₂z); `None`: no transverse shear flexibility (the
    /// four-node shell uses [`super::shell::KIRCHHOFF_SHEAR_FACTOR`], the triangle is Kirchhoff anyway).
    pub transverse_shear: Option<Matrix2<f64>>,
    /// Angle (rad) about the element normal from the side corner 1 → corner 2 (projected onto
    /// the element plane) to material axis 1, as Nastran's THETA.
    pub material_angle: f64,
    /// Distance (m) of the reference plane from the plane of the corner nodes along the element
    /// normal (Nastran ZOFFS): the corners carry the reference plane rigidly, u_ref = u + θ ×
    /// (offset n), so stiffness and mass become Tᵀ K T and Tᵀ M T.
    pub offset: f64,
}

impl ShellSection {
    /// The section of a homogeneous isotropic sheet: what a shell without a section uses
    /// (transverse shear k = 5/6 over the bending thickness), in any orientation.
    pub fn isotropic(material: &Material, thickness: f64, bending_thickness: f64) -> Self {
        let (e, nu) = (material.youngs_modulus, material.poisson_ratio);
        let iso = Matrix3::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, (1.0 - nu) / 2.0);
        let shear = SHEAR_CORRECTION * material.shear_modulus() * bending_thickness;
        Self {
            membrane: iso * (e * thickness / (1.0 - nu * nu)),
            bending: iso * (e * bending_thickness.powi(3) / (12.0 * (1.0 - nu * nu))),
            transverse_shear: Some(Matrix2::identity() * shear),
            material_angle: 0.0,
            offset: 0.0,
        }
    }

    /// Finite, symmetric positive definite A, D (and S when given), finite angle and offset.
    pub(crate) fn validate(&self, what: &str) -> Result<(), FeError> {
        let fail = |m: String| Err(FeError::InvalidInput(format!("{what}: {m}")));
        let spd3 = |m: &Matrix3<f64>| {
            m.iter().all(|v| v.is_finite())
                && (m - m.transpose()).abs().max() <= 1e-9 * m.abs().max()
                && m.cholesky().is_some()
        };
        if !spd3(&self.membrane) {
            return fail(format!(
                "membrane stiffness {} is not symmetric positive definite",
                self.membrane
            ));
        }
        if !spd3(&self.bending) {
            return fail(format!(
                "bending stiffness {} is not symmetric positive definite",
                self.bending
            ));
        }
        if let Some(s) = &self.transverse_shear {
            let ok = s.iter().all(|v| v.is_finite())
                && (s[(0, 1)] - s[(1, 0)]).abs() <= 1e-9 * s.abs().max()
                && s.cholesky().is_some();
            if !ok {
                return fail(format!(
                    "transverse shear stiffness {s} is not symmetric positive definite"
                ));
            }
        }
        if !(self.material_angle.is_finite() && self.offset.is_finite()) {
            return fail("material angle and offset must be finite".into());
        }
        Ok(())
    }

    /// Mean in-plane shear stiffness over all directions, (A₁₁ + A₂₂ − 2A₁₂ + 4A₃₃)/8: G t
    /// for an isotropic sheet; scales the drilling penalty independently of the orientation.
    pub(crate) fn mean_membrane_shear(&self) -> f64 {
        let a = &self.membrane;
        (a[(0, 0)] + a[(1, 1)] - 2.0 * a[(0, 1)] + 4.0 * a[(2, 2)]) / 8.0
    }
}
