//! Three-node flat shell: constant-strain membrane (CST) with the Hughes–Brezzi drilling
//! rotation of the four-node shell, discrete Kirchhoff triangle (DKT, Batoz, Bathe & Ho 1980)
//! for bending, lumped mass.
//!
//! Why DKT rather than a collapsed MITC4 or MITC3: the DKT passes the constant-curvature patch
//! test, cannot shear-lock (no transverse shear), and converges fast for the thin sheet metal
//! of a car body; a degenerate quadrilateral is distorted by construction and MITC3 is stiffer
//! for thin plates at equal mesh density. The price is that transverse shear flexibility is
//! ignored, which matters only for plates thicker than about a tenth of their span.
//!
//! Local DOFs per node: u, v, w, θx, θy, θz in the element frame (e1 along edge 1→2, e2,
//! normal); plate kinematics as the four-node shell: βx = θy, βy = −θx.

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::element::{BulkWriter, CheckLimits, Element, ElementMatrices, Finding};
use super::error::{require_non_negative, require_positive, FeError};
use super::mesh::{Mesh, TriShell};
use super::shell::{apply_offset, rotate_plane, without_index, write_sheet, DRILLING_FACTOR};

/// 18 × 18 element matrix, DOF order (ux uy uz rx ry rz) per corner node.
pub type Mat18 = SMatrix<f64, 18, 18>;

/// Geometry of a triangle in its plane.
#[derive(Debug, Clone, PartialEq)]
pub struct TriGeometry {
    /// Rows e1 (along edge 1→2), e2, normal of the element frame in global axes.
    pub frame: Matrix3<f64>,
    /// Corner coordinates in the element plane (corner 1 at the origin).
    pub local_xy: [[f64; 2]; 3],
    /// Area (m²).
    pub area: f64,
}

/// Frame, in-plane corners and area of triangle `index` with corners `p`.
pub fn geometry(index: usize, p: &[Vector3<f64>; 3]) -> Result<TriGeometry, FeError> {
    let edge = p[1] - p[0];
    let normal = edge.cross(&(p[2] - p[0]));
    let twice_area = normal.norm();
    if !(twice_area.is_finite() && twice_area > 1e-14 * edge.norm_squared().max(1e-300)) {
        return Err(FeError::Mesh(format!(
            "triangle {index}: degenerate (collinear or coincident corners)"
        )));
    }
    let n = normal / twice_area;
    let e1 = edge.normalize();
    let e2 = n.cross(&e1);
    let mut xy = [[0.0; 2]; 3];
    for i in 0..3 {
        let d = p[i] - p[0];
        xy[i] = [d.dot(&e1), d.dot(&e2)];
    }
    Ok(TriGeometry {
        frame: Matrix3::from_rows(&[e1.transpose(), e2.transpose(), n.transpose()]),
        local_xy: xy,
        area: 0.5 * twice_area,
    })
}

fn validate(index: usize, t: &TriShell) -> Result<(), FeError> {
    let m = &t.material;
    let name = |f: &str| format!("triangle {index}: {f}");
    require_positive(&name("thickness"), t.thickness)?;
    require_positive(&name("bending_thickness"), t.bending_thickness)?;
    require_non_negative(&name("density"), m.density)?;
    require_non_negative(&name("extra_mass_per_area"), t.extra_mass_per_area)?;
    if let Some(section) = &t.section {
        return section.validate(&name("section"));
    }
    require_positive(&name("youngs_modulus"), m.youngs_modulus)?;
    if !(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
        return Err(FeError::InvalidInput(format!(
            "triangle {index}: poisson_ratio must be in (-1, 0.5), got {}",
            m.poisson_ratio
        )));
    }
    Ok(())
}

/// Quadratic shape functions of the six-node triangle (corners 1..3, mid-sides 4 = 23,
/// 5 = 31, 6 = 12) and their derivatives at (ξ, η).
fn quadratic(xi: f64, eta: f64) -> ([f64; 6], [f64; 6], [f64; 6]) {
    let z = 1.0 - xi - eta;
    let n = [
        z * (2.0 * z - 1.0),
        xi * (2.0 * xi - 1.0),
        eta * (2.0 * eta - 1.0),
        4.0 * xi * eta,
        4.0 * eta * z,
        4.0 * xi * z,
    ];
    let dxi = [
        1.0 - 4.0 * z,
        4.0 * xi - 1.0,
        0.0,
        4.0 * eta,
        -4.0 * eta,
        4.0 * (z - xi),
    ];
    let deta = [
        1.0 - 4.0 * z,
        0.0,
        4.0 * eta - 1.0,
        4.0 * xi,
        4.0 * (z - eta),
        -4.0 * xi,
    ];
    (n, dxi, deta)
}

/// DKT side coefficients a, b, c, d, e for the mid-side nodes 4, 5, 6 (Batoz et al. 1980).
struct Sides {
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    d: [f64; 3],
    e: [f64; 3],
}

fn sides(xy: &[[f64; 2]; 3]) -> Sides {
    let mut s = Sides {
        a: [0.0; 3],
        b: [0.0; 3],
        c: [0.0; 3],
        d: [0.0; 3],
        e: [0.0; 3],
    };
    for (k, (i, j)) in [(1, 2), (2, 0), (0, 1)].into_iter().enumerate() {
        let (x, y) = (xy[i][0] - xy[j][0], xy[i][1] - xy[j][1]);
        let l2 = x * x + y * y;
        s.a[k] = -x / l2;
        s.b[k] = 0.75 * x * y / l2;
        s.c[k] = (0.25 * x * x - 0.5 * y * y) / l2;
        s.d[k] = -y / l2;
        s.e[k] = (0.25 * y * y - 0.5 * x * x) / l2;
    }
    s
}

/// βx and βy interpolation rows (over w, θx, θy per node) from the values `n` of the
/// quadratic shape functions (or of their derivatives: the map is linear).
fn beta_rows(s: &Sides, n: &[f64; 6]) -> ([f64; 9], [f64; 9]) {
    let (n4, n5, n6) = (n[3], n[4], n[5]);
    let (a, b, c, d, e) = (&s.a, &s.b, &s.c, &s.d, &s.e);
    let hx = [
        1.5 * (a[2] * n6 - a[1] * n5),
        b[1] * n5 + b[2] * n6,
        n[0] - c[1] * n5 - c[2] * n6,
        1.5 * (a[0] * n4 - a[2] * n6),
        b[2] * n6 + b[0] * n4,
        n[1] - c[2] * n6 - c[0] * n4,
        1.5 * (a[1] * n5 - a[0] * n4),
        b[0] * n4 + b[1] * n5,
        n[2] - c[0] * n4 - c[1] * n5,
    ];
    let hy = [
        1.5 * (d[2] * n6 - d[1] * n5),
        -n[0] + e[1] * n5 + e[2] * n6,
        -b[1] * n5 - b[2] * n6,
        1.5 * (d[0] * n4 - d[2] * n6),
        -n[1] + e[2] * n6 + e[0] * n4,
        -b[2] * n6 - b[0] * n4,
        1.5 * (d[1] * n5 - d[0] * n4),
        -n[2] + e[0] * n4 + e[1] * n5,
        -b[0] * n4 - b[1] * n5,
    ];
    (hx, hy)
}

/// Curvature matrix κ = (βx,x, βy,y, βx,y + βy,x) = B (w, θx, θy per node) at (ξ, η).
pub(crate) fn curvature_matrix(xy: &[[f64; 2]; 3], xi: f64, eta: f64) -> SMatrix<f64, 3, 9> {
    let s = sides(xy);
    let (_, dxi, deta) = quadratic(xi, eta);
    let (hx_xi, hy_xi) = beta_rows(&s, &dxi);
    let (hx_eta, hy_eta) = beta_rows(&s, &deta);
    let (x21, y21) = (xy[1][0] - xy[0][0], xy[1][1] - xy[0][1]);
    let (x31, y31) = (xy[2][0] - xy[0][0], xy[2][1] - xy[0][1]);
    let det = x21 * y31 - x31 * y21;
    // ∂/∂x = (y31 ∂ξ − y21 ∂η)/det, ∂/∂y = (−x31 ∂ξ + x21 ∂η)/det.
    let mut b = SMatrix::<f64, 3, 9>::zeros();
    for k in 0..9 {
        let bx_x = (y31 * hx_xi[k] - y21 * hx_eta[k]) / det;
        let bx_y = (-x31 * hx_xi[k] + x21 * hx_eta[k]) / det;
        let by_x = (y31 * hy_xi[k] - y21 * hy_eta[k]) / det;
        let by_y = (-x31 * hy_xi[k] + x21 * hy_eta[k]) / det;
        b[(0, k)] = bx_x;
        b[(1, k)] = by_y;
        b[(2, k)] = bx_y + by_x;
    }
    b
}

const GAUSS3: [(f64, f64); 3] = [
    (1.0 / 6.0, 1.0 / 6.0),
    (2.0 / 3.0, 1.0 / 6.0),
    (1.0 / 6.0, 2.0 / 3.0),
];

fn to_global(local: &Mat18, frame: &Matrix3<f64>) -> Mat18 {
    let mut t = Mat18::zeros();
    for b in 0..6 {
        t.fixed_view_mut::<3, 3>(3 * b, 3 * b).copy_from(frame);
    }
    t.transpose() * local * t
}

/// Global stiffness matrix of triangle `index` with corners `p`.
pub fn stiffness(index: usize, tri: &TriShell, p: &[Vector3<f64>; 3]) -> Result<Mat18, FeError> {
    validate(index, tri)?;
    let TriGeometry {
        frame,
        local_xy: xy,
        area,
    } = geometry(index, p)?;
    let (dm, db, gamma) = match &tri.section {
        None => {
            let mat = &tri.material;
            let (e, nu) = (mat.youngs_modulus, mat.poisson_ratio);
            let iso = Matrix3::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, (1.0 - nu) / 2.0);
            let dm = iso * (e * tri.thickness / (1.0 - nu * nu));
            let db = iso * (e * tri.bending_thickness.powi(3) / (12.0 * (1.0 - nu * nu)));
            (
                dm,
                db,
                DRILLING_FACTOR * mat.shear_modulus() * tri.thickness,
            )
        }
        // e1 runs along G1 → G2, from which Nastran measures THETA; the DKT has no transverse
        // shear, so the section's shear matrix is not used.
        Some(s) => (
            rotate_plane(&s.membrane, s.material_angle),
            rotate_plane(&s.bending, s.material_angle),
            DRILLING_FACTOR * s.mean_membrane_shear(),
        ),
    };

    // Constant membrane strain: ∂Nᵢ/∂x = yⱼₖ / 2A, ∂Nᵢ/∂y = xₖⱼ / 2A.
    let twice = 2.0 * area;
    let mut dndx = [0.0; 3];
    let mut dndy = [0.0; 3];
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        dndx[i] = (xy[j][1] - xy[k][1]) / twice;
        dndy[i] = (xy[k][0] - xy[j][0]) / twice;
    }
    let mut bm = SMatrix::<f64, 3, 18>::zeros();
    for i in 0..3 {
        let (u, v) = (6 * i, 6 * i + 1);
        bm[(0, u)] = dndx[i];
        bm[(1, v)] = dndy[i];
        bm[(2, u)] = dndy[i];
        bm[(2, v)] = dndx[i];
    }
    let mut k = bm.transpose() * dm * bm * area;
    for &(xi, eta) in &GAUSS3 {
        let weight = area / 3.0;
        let n = [1.0 - xi - eta, xi, eta];
        let mut bd = SMatrix::<f64, 1, 18>::zeros();
        let plate = curvature_matrix(&xy, xi, eta);
        let mut bb = SMatrix::<f64, 3, 18>::zeros();
        for i in 0..3 {
            bd[(0, 6 * i)] = 0.5 * dndy[i];
            bd[(0, 6 * i + 1)] = -0.5 * dndx[i];
            bd[(0, 6 * i + 5)] = n[i];
            for r in 0..3 {
                for (c, local) in [(2, 0), (3, 1), (4, 2)] {
                    bb[(r, 6 * i + c)] = plate[(r, 3 * i + local)];
                }
            }
        }
        k += (bb.transpose() * db * bb + bd.transpose() * bd * gamma) * weight;
    }
    if let Some(offset) = tri.section.as_ref().map(|s| s.offset).filter(|&z| z != 0.0) {
        apply_offset(&mut k, 3, offset);
    }
    Ok(to_global(&k, &frame))
}

/// Global lumped mass matrix: a third of the panel mass and of its rotary inertia
/// (mass per area × t_b²/12, isotropic) per corner, like the four-node shell.
pub fn lumped_mass(index: usize, tri: &TriShell, p: &[Vector3<f64>; 3]) -> Result<Mat18, FeError> {
    validate(index, tri)?;
    let TriGeometry { frame, area, .. } = geometry(index, p)?;
    let areal = tri.material.density * tri.thickness + tri.extra_mass_per_area;
    let rotary = areal * tri.bending_thickness.powi(2) / 12.0;
    let mut m = Mat18::zeros();
    for i in 0..3 {
        for d in 0..3 {
            m[(6 * i + d, 6 * i + d)] = areal * area / 3.0;
            m[(6 * i + 3 + d, 6 * i + 3 + d)] = rotary * area / 3.0;
        }
    }
    match tri.section.as_ref().map(|s| s.offset).filter(|&z| z != 0.0) {
        // The mass sits on the offset reference plane, carried rigidly by the corners.
        Some(offset) => {
            apply_offset(&mut m, 3, offset);
            Ok(to_global(&m, &frame))
        }
        None => Ok(m),
    }
}

impl Element for TriShell {
    const NAME: &'static str = "triangle";

    fn nodes(&self) -> Vec<usize> {
        self.nodes.to_vec()
    }

    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        let what = format!("triangle {index}");
        let p = mesh.positions(&what, &self.nodes)?;
        Ok(ElementMatrices::stiffness_and_mass(
            &stiffness(index, self, &p)?,
            &lumped_mass(index, self, &p)?,
        ))
    }

    fn check_shape(
        &self,
        index: usize,
        _mesh: &Mesh,
        points: &[Vector3<f64>],
        limits: &CheckLimits,
    ) -> Vec<Finding> {
        match geometry(index, &[points[0], points[1], points[2]]) {
            Err(e) => vec![Finding::Wrong(without_index(&e, "triangle", index))],
            Ok(g) if g.area < limits.min_shell_area => vec![Finding::Wrong(format!(
                "degenerate (area {:.3e} m²)",
                g.area
            ))],
            Ok(_) => Vec::new(),
        }
    }

    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let sheet = [
            self.thickness,
            self.bending_thickness,
            self.extra_mass_per_area,
        ];
        let what = format!("triangle {index}");
        write_sheet(
            deck,
            "CTRIA3",
            &what,
            &self.material,
            sheet,
            self.section.as_deref(),
            &self.nodes,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::mesh::Material;

    fn tri() -> TriShell {
        TriShell {
            nodes: [0, 1, 2],
            material: Material::STEEL,
            thickness: 0.002,
            bending_thickness: 0.002,
            extra_mass_per_area: 0.0,
            section: None,
        }
    }

    #[test]
    fn dkt_reproduces_constant_curvature_exactly() {
        // w = a x² + b x y + c y²: θx = w,y, θy = −w,x; κ = (−2a, −2c, −2b) everywhere.
        let xy = [[0.1, -0.2], [1.3, 0.1], [0.4, 0.9]];
        let (a, b, c) = (0.7, -0.4, 1.1);
        let mut u = SMatrix::<f64, 9, 1>::zeros();
        for (i, &[x, y]) in xy.iter().enumerate() {
            u[3 * i] = a * x * x + b * x * y + c * y * y;
            u[3 * i + 1] = b * x + 2.0 * c * y;
            u[3 * i + 2] = -(2.0 * a * x + b * y);
        }
        for (xi, eta) in [(0.2, 0.3), (0.0, 0.0), (0.7, 0.1), (1.0 / 3.0, 1.0 / 3.0)] {
            let kappa = curvature_matrix(&xy, xi, eta) * u;
            for (got, want) in kappa.iter().zip([-2.0 * a, -2.0 * c, -2.0 * b]) {
                assert!(
                    (got - want).abs() < 1e-12,
                    "{got} vs {want} at ({xi}, {eta})"
                );
            }
        }
    }

    #[test]
    fn exactly_six_rigid_body_modes_in_any_orientation() {
        let r = nalgebra::Rotation3::from_euler_angles(0.4, -0.7, 1.1);
        let p = [
            r * Vector3::new(0.0, 0.0, 0.0),
            r * Vector3::new(0.9, 0.2, 0.0),
            r * Vector3::new(0.3, 0.8, 0.0),
        ];
        let k = stiffness(0, &tri(), &p).unwrap();
        let scale = k.abs().max();
        let eig = k.symmetric_eigenvalues();
        assert_eq!(eig.iter().filter(|v| v.abs() < 1e-9 * scale).count(), 6);
        assert!(eig.iter().all(|v| *v > -1e-9 * scale));
    }

    #[test]
    fn offset_orthotropic_triangle_keeps_six_rigid_body_modes() {
        let r = nalgebra::Rotation3::from_euler_angles(-0.3, 0.6, 0.2);
        let p = [
            r * Vector3::new(0.0, 0.0, 0.0),
            r * Vector3::new(0.9, 0.2, 0.0),
            r * Vector3::new(0.3, 0.8, 0.0),
        ];
        let mut t = tri();
        let ortho = Matrix3::new(9.0e8, 1.0e8, 0.0, 1.0e8, 2.0e8, 0.0, 0.0, 0.0, 1.5e8);
        t.section = Some(Box::new(crate::fe::shell::ShellSection {
            membrane: ortho,
            bending: ortho * 1e-6,
            transverse_shear: None,
            material_angle: 0.4,
            offset: -0.004,
        }));
        let k = stiffness(0, &t, &p).unwrap();
        let scale = k.abs().max();
        let eig = k.symmetric_eigenvalues();
        assert_eq!(eig.iter().filter(|v| v.abs() < 1e-9 * scale).count(), 6);
        assert!(eig.iter().all(|v| *v > -1e-9 * scale));
    }

    #[test]
    fn collinear_corners_are_rejected_with_the_index() {
        let p = [Vector3::zeros(), Vector3::x(), 2.0 * Vector3::x()];
        let err = stiffness(5, &tri(), &p).unwrap_err().to_string();
        assert!(err.contains("triangle 5"), "{err}");
    }
}
