//! Four-node flat shell: bilinear membrane with incompatible modes (Wilson–Taylor QM6, no
//! parasitic shear in in-plane bending) and a Hughes–Brezzi drilling rotation, MITC4
//! (Bathe–Dvorkin) Mindlin plate that does not shear-lock, lumped mass.
//!
//! Local DOFs per node: u, v, w, θx, θy, θz in the element frame (e1, e2, normal).
//! Plate kinematics: the section rotations are βx = θy, βy = −θx.

use nalgebra::{Matrix2, Matrix3, SMatrix, Vector3};

use super::element::{
    BulkWriter, CheckLimits, Element, ElementMatrices, Field, Finding, ShapeTest,
};
use super::error::{require_non_negative, require_positive, FeError};
use super::mesh::{Material, Mesh, Shell};
pub use super::section::ShellSection;
use super::section::SHEAR_CORRECTION;

/// 24 × 24 element matrix, DOF order (ux uy uz rx ry rz) per corner node.
pub type Mat24 = SMatrix<f64, 24, 24>;

/// Drilling penalty γ = α G t (Hughes & Brezzi 1989). The result is insensitive to α over
/// decades; α = 0.01 keeps membrane behaviour unaffected while removing the singular θz.
pub const DRILLING_FACTOR: f64 = 0.01;

/// Transverse shear stiffness of a section without transverse shear flexibility (Nastran
/// PSHELL with MID3 blank), as a multiple of the largest bending stiffness over the element
/// area: the shear compliance is then about 1e-5 of the bending compliance of a single
/// element (less for a structure spanning many), which is Kirchhoff behaviour; MITC4 does not
/// lock in that limit.
pub const KIRCHHOFF_SHEAR_FACTOR: f64 = 1.0e5;

/// A plane constitutive matrix (engineering strains ε_x, ε_y, γ_xy) given in axes whose 1 axis
/// lies at `angle` from x, expressed in (x, y): Tᵀ C T with ε₁₂ = T ε_xy.
pub(crate) fn rotate_plane(c: &Matrix3<f64>, angle: f64) -> Matrix3<f64> {
    if angle == 0.0 {
        return *c;
    }
    let (s, co) = angle.sin_cos();
    let t = Matrix3::new(
        co * co,
        s * s,
        co * s,
        s * s,
        co * co,
        -co * s,
        -2.0 * co * s,
        2.0 * co * s,
        co * co - s * s,
    );
    t.transpose() * c * t
}

/// A transverse shear matrix given in axes rotated by `angle`, expressed in (x, y).
pub(crate) fn rotate_shear(c: &Matrix2<f64>, angle: f64) -> Matrix2<f64> {
    if angle == 0.0 {
        return *c;
    }
    let (s, co) = angle.sin_cos();
    let r = Matrix2::new(co, s, -s, co);
    r.transpose() * c * r
}

/// Tᵀ A T for the rigid offset T of the reference plane by `offset` along the local normal,
/// for `nodes` corners (local DOFs u v w θx θy θz): u_ref = u + offset θy, v_ref = v − offset
/// θx. T is the identity plus two entries per corner, so the product is done by column and row
/// updates instead of two dense products (this runs for every offset shell of a large deck).
pub(crate) fn apply_offset<const D: usize>(a: &mut SMatrix<f64, D, D>, nodes: usize, offset: f64) {
    for i in 0..nodes {
        let (u, v, rx, ry) = (6 * i, 6 * i + 1, 6 * i + 3, 6 * i + 4);
        for r in 0..D {
            a[(r, ry)] += offset * a[(r, u)];
            a[(r, rx)] -= offset * a[(r, v)];
        }
    }
    for i in 0..nodes {
        let (u, v, rx, ry) = (6 * i, 6 * i + 1, 6 * i + 3, 6 * i + 4);
        for c in 0..D {
            a[(ry, c)] += offset * a[(u, c)];
            a[(rx, c)] -= offset * a[(v, c)];
        }
    }
}

const XI: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
const ETA: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];

/// Geometry of a flat shell projected onto its mean plane.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellGeometry {
    /// Rows e1, e2, normal of the element frame in global axes.
    pub frame: Matrix3<f64>,
    /// Corner coordinates in the element plane.
    pub local_xy: [[f64; 2]; 4],
    /// Area of the projected quadrilateral (m²).
    pub area: f64,
    /// Largest corner distance from the mean plane divided by √area.
    pub warp: f64,
    /// Smallest / largest Jacobian determinant at the corners (≤ 0: inverted or degenerate).
    pub jacobian_ratio: f64,
}

fn shape(xi: f64, eta: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let mut n = [0.0; 4];
    let mut dxi = [0.0; 4];
    let mut deta = [0.0; 4];
    for i in 0..4 {
        n[i] = 0.25 * (1.0 + xi * XI[i]) * (1.0 + eta * ETA[i]);
        dxi[i] = 0.25 * XI[i] * (1.0 + eta * ETA[i]);
        deta[i] = 0.25 * ETA[i] * (1.0 + xi * XI[i]);
    }
    (n, dxi, deta)
}

fn jacobian(xy: &[[f64; 2]; 4], dxi: &[f64; 4], deta: &[f64; 4]) -> Matrix2<f64> {
    let mut j = Matrix2::zeros();
    for i in 0..4 {
        j[(0, 0)] += dxi[i] * xy[i][0];
        j[(0, 1)] += dxi[i] * xy[i][1];
        j[(1, 0)] += deta[i] * xy[i][0];
        j[(1, 1)] += deta[i] * xy[i][1];
    }
    j
}

/// Frame, projected corners and quality measures of shell `index` with corners `p`.
pub fn geometry(index: usize, p: &[Vector3<f64>; 4]) -> Result<ShellGeometry, FeError> {
    let normal = (p[2] - p[0]).cross(&(p[3] - p[1]));
    let nn = normal.norm();
    if !(nn.is_finite() && nn > 1e-14) {
        return Err(FeError::Mesh(format!(
            "shell {index}: degenerate (zero diagonal cross product)"
        )));
    }
    let n = normal / nn;
    let d1 = p[1] + p[2] - p[0] - p[3];
    let e1 = d1 - n * n.dot(&d1);
    let e1n = e1.norm();
    if e1n.is_nan() || e1n <= 1e-14 {
        return Err(FeError::Mesh(format!(
            "shell {index}: degenerate (collapsed edge direction)"
        )));
    }
    let e1 = e1 / e1n;
    let e2 = n.cross(&e1);
    let c = (p[0] + p[1] + p[2] + p[3]) / 4.0;
    let mut local_xy = [[0.0; 2]; 4];
    let mut max_offset: f64 = 0.0;
    for i in 0..4 {
        let d = p[i] - c;
        local_xy[i] = [d.dot(&e1), d.dot(&e2)];
        max_offset = max_offset.max(d.dot(&n).abs());
    }
    let area = 0.5 * nn;
    let mut dets = [0.0; 4];
    for i in 0..4 {
        let (_, dxi, deta) = shape(XI[i], ETA[i]);
        dets[i] = jacobian(&local_xy, &dxi, &deta).determinant();
    }
    let max_det = dets.iter().cloned().fold(f64::MIN, f64::max);
    let min_det = dets.iter().cloned().fold(f64::MAX, f64::min);
    let jacobian_ratio = if max_det > 0.0 {
        min_det / max_det
    } else {
        -1.0
    };
    Ok(ShellGeometry {
        frame: Matrix3::from_rows(&[e1.transpose(), e2.transpose(), n.transpose()]),
        local_xy,
        area,
        warp: max_offset / area.sqrt(),
        jacobian_ratio,
    })
}

fn validate(index: usize, shell: &Shell) -> Result<(), FeError> {
    let m = &shell.material;
    let name = |f: &str| format!("shell {index}: {f}");
    require_positive(&name("thickness"), shell.thickness)?;
    require_positive(&name("bending_thickness"), shell.bending_thickness)?;
    require_non_negative(&name("density"), m.density)?;
    require_non_negative(&name("extra_mass_per_area"), shell.extra_mass_per_area)?;
    if let Some(section) = &shell.section {
        return section.validate(&name("section"));
    }
    require_positive(&name("youngs_modulus"), m.youngs_modulus)?;
    if !(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
        return Err(FeError::InvalidInput(format!(
            "shell {index}: poisson_ratio must be in (-1, 0.5), got {}",
            m.poisson_ratio
        )));
    }
    Ok(())
}

fn to_global(local: &Mat24, frame: &Matrix3<f64>) -> Mat24 {
    let mut t = Mat24::zeros();
    for b in 0..8 {
        t.fixed_view_mut::<3, 3>(3 * b, 3 * b).copy_from(frame);
    }
    t.transpose() * local * t
}

/// Covariant transverse shear strain row e_r (r = ξ if `along_xi`, else η) at (ξ, η).
fn covariant_shear_row(xy: &[[f64; 2]; 4], xi: f64, eta: f64, along_xi: bool) -> [f64; 24] {
    let (n, dxi, deta) = shape(xi, eta);
    let j = jacobian(xy, &dxi, &deta);
    let (dn, row) = if along_xi { (dxi, 0) } else { (deta, 1) };
    let (x_r, y_r) = (j[(row, 0)], j[(row, 1)]);
    let mut out = [0.0; 24];
    for i in 0..4 {
        out[6 * i + 2] = dn[i];
        out[6 * i + 4] = n[i] * x_r;
        out[6 * i + 3] = -n[i] * y_r;
    }
    out
}

/// Global stiffness matrix of shell `index` with corners `p`.
///
/// Long on purpose: one element formulation (membrane, drilling, plate bending, transformation) evaluated at shared Gauss points.
pub fn stiffness(index: usize, shell: &Shell, p: &[Vector3<f64>; 4]) -> Result<Mat24, FeError> {
    validate(index, shell)?;
    let geo = geometry(index, p)?;
    if geo.jacobian_ratio <= 0.0 {
        return Err(FeError::Mesh(format!(
            "shell {index}: inverted or non-convex corner (Jacobian ratio {:.3})",
            geo.jacobian_ratio
        )));
    }
    let xy = &geo.local_xy;
    let (dm, db, ds, gamma) = constitutive(shell, &geo, p);

    let tie_xi = [
        covariant_shear_row(xy, 0.0, -1.0, true),
        covariant_shear_row(xy, 0.0, 1.0, true),
    ];
    let tie_eta = [
        covariant_shear_row(xy, -1.0, 0.0, false),
        covariant_shear_row(xy, 1.0, 0.0, false),
    ];

    // Incompatible membrane modes (1 − ξ², 1 − η² for u and v) use the centre Jacobian and the
    // det0/det factor (Taylor, Beresford & Wilson 1976), so they integrate to zero strain and the
    // element passes the patch test while bending in its plane without parasitic shear.
    let (_, dxi0, deta0) = shape(0.0, 0.0);
    let j0 = jacobian(xy, &dxi0, &deta0);
    let det0 = j0.determinant();
    let inv0 = j0
        .try_inverse()
        .ok_or_else(|| FeError::Mesh(format!("shell {index}: singular Jacobian at the centre")))?;
    let gp = 1.0 / 3.0_f64.sqrt();
    let mut k = Mat24::zeros();
    let mut k_membrane = Mat24::zeros();
    let mut k_coupling = SMatrix::<f64, 24, 4>::zeros();
    let mut k_internal = SMatrix::<f64, 4, 4>::zeros();
    for &(xi, eta) in &[(-gp, -gp), (gp, -gp), (gp, gp), (-gp, gp)] {
        let (n, dxi, deta) = shape(xi, eta);
        let j = jacobian(xy, &dxi, &deta);
        let det = j.determinant();
        let mut bi = SMatrix::<f64, 3, 4>::zeros();
        for (mode, (dp_dxi, dp_deta)) in [(-2.0 * xi, 0.0), (0.0, -2.0 * eta)]
            .into_iter()
            .enumerate()
        {
            let scale = det0 / det;
            let dp_dx = scale * (inv0[(0, 0)] * dp_dxi + inv0[(0, 1)] * dp_deta);
            let dp_dy = scale * (inv0[(1, 0)] * dp_dxi + inv0[(1, 1)] * dp_deta);
            // Internal DOFs: u-modes 0, 1; v-modes 2, 3.
            bi[(0, mode)] = dp_dx;
            bi[(2, mode)] = dp_dy;
            bi[(1, 2 + mode)] = dp_dy;
            bi[(2, 2 + mode)] = dp_dx;
        }
        let inv = j.try_inverse().ok_or_else(|| {
            FeError::Mesh(format!("shell {index}: singular Jacobian at a Gauss point"))
        })?;
        let mut dndx = [0.0; 4];
        let mut dndy = [0.0; 4];
        for i in 0..4 {
            dndx[i] = inv[(0, 0)] * dxi[i] + inv[(0, 1)] * deta[i];
            dndy[i] = inv[(1, 0)] * dxi[i] + inv[(1, 1)] * deta[i];
        }
        let mut bm = SMatrix::<f64, 3, 24>::zeros();
        let mut bb = SMatrix::<f64, 3, 24>::zeros();
        let mut bd = SMatrix::<f64, 1, 24>::zeros();
        for i in 0..4 {
            let (u, v, rx, ry, rz) = (6 * i, 6 * i + 1, 6 * i + 3, 6 * i + 4, 6 * i + 5);
            bm[(0, u)] = dndx[i];
            bm[(1, v)] = dndy[i];
            bm[(2, u)] = dndy[i];
            bm[(2, v)] = dndx[i];
            bb[(0, ry)] = dndx[i];
            bb[(1, rx)] = -dndy[i];
            bb[(2, ry)] = dndy[i];
            bb[(2, rx)] = -dndx[i];
            bd[(0, u)] = 0.5 * dndy[i];
            bd[(0, v)] = -0.5 * dndx[i];
            bd[(0, rz)] = n[i];
        }
        let mut covariant = SMatrix::<f64, 2, 24>::zeros();
        for c in 0..24 {
            covariant[(0, c)] = 0.5 * (1.0 - eta) * tie_xi[0][c] + 0.5 * (1.0 + eta) * tie_xi[1][c];
            covariant[(1, c)] = 0.5 * (1.0 - xi) * tie_eta[0][c] + 0.5 * (1.0 + xi) * tie_eta[1][c];
        }
        let bs = inv * covariant;
        k_membrane += bm.transpose() * dm * bm * det;
        k_coupling += bm.transpose() * dm * bi * det;
        k_internal += bi.transpose() * dm * bi * det;
        let shear = match &ds {
            TransverseShear::Isotropic(ds) => bs.transpose() * bs * *ds,
            TransverseShear::General(s) => bs.transpose() * s * bs,
        };
        k += (bb.transpose() * db * bb + shear + bd.transpose() * bd * gamma) * det;
    }
    // Static condensation of the internal modes.
    let internal_inv = k_internal.try_inverse().ok_or_else(|| {
        FeError::Mesh(format!(
            "shell {index}: singular incompatible-mode stiffness"
        ))
    })?;
    k += k_membrane - k_coupling * internal_inv * k_coupling.transpose();
    if let Some(offset) = shell
        .section
        .as_ref()
        .map(|s| s.offset)
        .filter(|&z| z != 0.0)
    {
        apply_offset(&mut k, 4, offset);
    }
    Ok(to_global(&k, &geo.frame))
}

enum TransverseShear {
    Isotropic(f64),
    General(Matrix2<f64>),
}

/// Membrane, bending, transverse shear matrices and drilling penalty in element axes.
fn constitutive(
    shell: &Shell,
    geo: &ShellGeometry,
    p: &[Vector3<f64>; 4],
) -> (Matrix3<f64>, Matrix3<f64>, TransverseShear, f64) {
    let Some(section) = &shell.section else {
        let mat = &shell.material;
        let (e, nu, t) = (mat.youngs_modulus, mat.poisson_ratio, shell.thickness);
        let tb = shell.bending_thickness;
        let g = mat.shear_modulus();
        let iso = Matrix3::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, (1.0 - nu) / 2.0);
        let dm = iso * (e * t / (1.0 - nu * nu));
        let db = iso * (e * tb.powi(3) / (12.0 * (1.0 - nu * nu)));
        let ds = SHEAR_CORRECTION * g * tb;
        return (
            dm,
            db,
            TransverseShear::Isotropic(ds),
            DRILLING_FACTOR * g * t,
        );
    };
    // THETA is measured from the side G1 → G2, not from this element's e1 (the line joining
    // the side midpoints), so the angle between the two is added.
    let side = p[1] - p[0];
    let along = geo.frame * side;
    let angle = section.material_angle + along[1].atan2(along[0]);
    let dm = rotate_plane(&section.membrane, angle);
    let db = rotate_plane(&section.bending, angle);
    let ds = match &section.transverse_shear {
        Some(s) => rotate_shear(s, angle),
        None => {
            Matrix2::identity() * (KIRCHHOFF_SHEAR_FACTOR * db[(0, 0)].max(db[(1, 1)]) / geo.area)
        }
    };
    let gamma = DRILLING_FACTOR * section.mean_membrane_shear();
    (dm, db, TransverseShear::General(ds), gamma)
}

/// Global lumped mass matrix of shell `index`: each corner carries the row sum of the consistent
/// translational mass (∫ N_i ρ t dA) and the same share of the rotary inertia (mass per area
/// × t_b²/12) about all three axes (isotropic, so it stays diagonal in global axes), on the
/// reference plane (offset by the section's offset, if any).
pub fn lumped_mass(index: usize, shell: &Shell, p: &[Vector3<f64>; 4]) -> Result<Mat24, FeError> {
    validate(index, shell)?;
    let geo = geometry(index, p)?;
    let areal = shell.material.density * shell.thickness + shell.extra_mass_per_area;
    let rotary = areal * shell.bending_thickness.powi(2) / 12.0;
    let gp = 1.0 / 3.0_f64.sqrt();
    let mut share = [0.0; 4];
    for &(xi, eta) in &[(-gp, -gp), (gp, -gp), (gp, gp), (-gp, gp)] {
        let (n, dxi, deta) = shape(xi, eta);
        let det = jacobian(&geo.local_xy, &dxi, &deta).determinant();
        for i in 0..4 {
            share[i] += n[i] * det;
        }
    }
    let mut m = Mat24::zeros();
    for i in 0..4 {
        for d in 0..3 {
            m[(6 * i + d, 6 * i + d)] = areal * share[i];
            m[(6 * i + 3 + d, 6 * i + 3 + d)] = rotary * share[i];
        }
    }
    match shell
        .section
        .as_ref()
        .map(|s| s.offset)
        .filter(|&z| z != 0.0)
    {
        // The lumped mass sits on the reference plane; the corners carry it rigidly, which
        // couples translation and rotation and adds m z0² of rotary inertia.
        Some(offset) => {
            apply_offset(&mut m, 4, offset);
            Ok(to_global(&m, &geo.frame))
        }
        None => Ok(m),
    }
}

impl Element for Shell {
    const NAME: &'static str = "shell";

    fn nodes(&self) -> Vec<usize> {
        self.nodes.to_vec()
    }

    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        let what = format!("shell {index}");
        let p = mesh.positions(&what, &self.nodes)?;
        Ok(ElementMatrices::stiffness_and_mass(
            &stiffness(index, self, &p)?,
            &lumped_mass(index, self, &p)?,
        ))
    }

    /// Refused: repeated corners, a geometry the element cannot be formed on, an area below
    /// the limit, an inverted corner; the poor-shape tests (warp and Jacobian ratio, and when
    /// poor shapes are only counted taper and skew) are findings of their own.
    fn check_shape(
        &self,
        index: usize,
        _mesh: &Mesh,
        points: &[Vector3<f64>],
        limits: &CheckLimits,
    ) -> Vec<Finding> {
        let mut distinct = self.nodes.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 4 {
            return vec![Finding::RepeatedNode];
        }
        let corners = [points[0], points[1], points[2], points[3]];
        let g = match geometry(index, &corners) {
            Err(e) => return vec![Finding::Wrong(without_index(&e, "shell", index))],
            Ok(g) => g,
        };
        if g.area < limits.min_shell_area {
            return vec![Finding::Wrong(format!(
                "degenerate (area {:.3e} m²)",
                g.area
            ))];
        }
        if g.jacobian_ratio <= 0.0 {
            return vec![Finding::Wrong(format!(
                "inverted or degenerate (corner Jacobian ratio {:.3} ≤ 0: a corner angle of \
                 180° or more; check the corner order)",
                g.jacobian_ratio
            ))];
        }
        let mut found = Vec::new();
        if g.warp > limits.max_warp {
            found.push(Finding::Poor(ShapeTest::Warp, g.warp));
        }
        if g.jacobian_ratio < limits.min_jacobian_ratio {
            found.push(Finding::Poor(ShapeTest::JacobianRatio, g.jacobian_ratio));
        }
        let (taper, skew) = taper_and_skew(&corners);
        if limits.max_taper.is_some_and(|t| taper > t) {
            found.push(Finding::Poor(ShapeTest::Taper, taper));
        }
        if limits.min_skew_angle_deg.is_some_and(|s| skew < s) {
            found.push(Finding::Poor(ShapeTest::Skew, skew));
        }
        found
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
        let what = format!("shell {index}");
        write_sheet(
            deck,
            "CQUAD4",
            &what,
            &self.material,
            sheet,
            self.section.as_deref(),
            &self.nodes,
        )
    }
}

/// `e`'s message without the `"{name} {index}: "` the element code puts in front (the caller
/// names the element itself).
pub(crate) fn without_index(e: &FeError, name: &str, index: usize) -> String {
    let (FeError::Mesh(m) | FeError::InvalidInput(m) | FeError::Numerical(m) | FeError::Io(m)) = e;
    m.strip_prefix(&format!("{name} {index}: "))
        .unwrap_or(m)
        .to_string()
}

/// Taper (1 − 2·smallest corner triangle / area) and skew angle (degrees, between the lines
/// joining midpoints of opposite sides) of a quadrilateral.
fn taper_and_skew(p: &[Vector3<f64>; 4]) -> (f64, f64) {
    let area = 0.5 * (p[2] - p[0]).cross(&(p[3] - p[1])).norm();
    let corner = |i: usize| {
        let (a, b, c) = (p[(i + 3) % 4], p[i], p[(i + 1) % 4]);
        0.5 * (a - b).cross(&(c - b)).norm()
    };
    let smallest = (0..4).map(corner).fold(f64::INFINITY, f64::min);
    let taper = 1.0 - 2.0 * smallest / area;
    let m = |i: usize| (p[i] + p[(i + 1) % 4]) / 2.0;
    let (u, v) = (m(2) - m(0), m(3) - m(1));
    let cos = (u.dot(&v) / (u.norm() * v.norm())).abs().min(1.0);
    (taper, cos.acos().to_degrees())
}

/// A CQUAD4 or CTRIA3 (`card`) of an isotropic sheet `[thickness, bending thickness,
/// non-structural mass]` with its PSHELL and MAT1, with THETA and ZOFFS when the sheet is
/// offset.
pub(crate) fn write_sheet(
    deck: &mut dyn BulkWriter,
    card: &str,
    what: &str,
    material: &Material,
    sheet: [f64; 3],
    section: Option<&ShellSection>,
    nodes: &[usize],
) -> Result<(), FeError> {
    let placement = placement(what, material, sheet, section)?;
    let [t, bending_t, nsm] = sheet;
    // PSHELL with MID1 = MID2 = MID3, so Nastran also includes transverse shear, like the
    // four-node shell.
    let mid = deck.material(material)?;
    let ratio = (bending_t / t).powi(3);
    // The mesh's sheet shears over 5/6 of its bending thickness, Nastran over TS/T·T.
    let ts_t = 5.0 / 6.0 * bending_t / t;
    let pid = deck.property("PSHELL", &[mid as f64, t, ratio, nsm], &|pid| {
        vec![
            Field::Int(pid),
            Field::Int(mid),
            Field::Real(t),
            Field::Int(mid),
            Field::Real(ratio),
            Field::Int(mid),
            Field::Real(ts_t),
            Field::Real(nsm),
        ]
    })?;
    let mut fields = vec![deck.element_id(), Field::Int(pid)];
    for &n in nodes {
        fields.push(deck.grid(what, n)?);
    }
    if let Some([theta, zoffs]) = placement {
        fields.push(Field::Real(theta.to_degrees()));
        fields.push(Field::Real(zoffs));
    }
    deck.card(card, &fields)
}

/// THETA (rad) and ZOFFS of a sheet with a section, `None` without one.
///
/// The writer emits isotropic PSHELL/MAT1 sheets only, so a section is written when it is that
/// sheet placed by an offset and a material angle (what production decks carry: panels meshed on
/// a surface rather than the mid-plane); a general section (MAT2/MAT8, separate bending or shear
/// materials) would be written wrong, so it is refused. The comparison allows rounding (1e-12 of
/// each matrix's largest entry) since a section read from a deck is built in another order.
fn placement(
    what: &str,
    material: &Material,
    [t, bending_t, _]: [f64; 3],
    section: Option<&ShellSection>,
) -> Result<Option<[f64; 2]>, FeError> {
    let Some(section) = section else {
        return Ok(None);
    };
    let sheet = ShellSection::isotropic(material, t, bending_t);
    let close = |a: &[f64], b: &[f64], tol: f64| {
        let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * scale)
    };
    // Nastran's default TS/T is 0.833333, 5/6 to 4e-7: the reader also takes it as the sheet's.
    let shear = match (&section.transverse_shear, &sheet.transverse_shear) {
        (Some(a), Some(b)) => close(a.as_slice(), b.as_slice(), 1e-5),
        _ => false,
    };
    if !(close(
        section.membrane.as_slice(),
        sheet.membrane.as_slice(),
        1e-12,
    ) && close(section.bending.as_slice(), sheet.bending.as_slice(), 1e-12)
        && shear)
    {
        return Err(FeError::InvalidInput(format!(
            "{what}: shells with a general section (anisotropic materials, separate bending or \
             shear material) are not written; an isotropic sheet with an offset is"
        )));
    }
    Ok(Some([section.material_angle, section.offset]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::mesh::Material;
    use crate::fe::test_support::rigid_motion;

    fn plate() -> Shell {
        Shell {
            nodes: [0, 1, 2, 3],
            material: Material::STEEL,
            thickness: 0.002,
            bending_thickness: 0.002,
            extra_mass_per_area: 0.0,
            section: None,
        }
    }

    fn corners() -> [Vector3<f64>; 4] {
        // A skew, tilted quadrilateral exercises the frame and the covariant shear interpolation.
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.5, 0.8);
        [
            r * Vector3::new(0.0, 0.0, 0.0),
            r * Vector3::new(1.1, 0.1, 0.0),
            r * Vector3::new(1.3, 0.9, 0.0),
            r * Vector3::new(-0.1, 1.0, 0.0),
        ]
    }

    #[test]
    fn rigid_body_motions_cost_no_energy_and_there_are_exactly_six() {
        let p = corners();
        let k = stiffness(0, &plate(), &p).unwrap();
        let scale = k.abs().max();
        for mode in 0..6 {
            let u = SMatrix::<f64, 24, 1>::from_column_slice(&rigid_motion(&p, mode));
            assert!(
                (k * u).norm() < 1e-8 * scale,
                "rigid mode {mode} strains the shell"
            );
        }
        let eig = k.symmetric_eigenvalues();
        let zero = eig.iter().filter(|v| v.abs() < 1e-9 * scale).count();
        assert_eq!(
            zero, 6,
            "a single shell must have exactly six zero-energy modes"
        );
    }

    #[test]
    fn isotropic_section_in_any_orientation_is_the_plain_sheet() {
        let p = corners();
        let plain = plate();
        let mut general = plate();
        let mut section = ShellSection::isotropic(&plain.material, 0.002, 0.002);
        section.material_angle = 0.7;
        general.section = Some(Box::new(section));
        let (a, b) = (
            stiffness(0, &plain, &p).unwrap(),
            stiffness(0, &general, &p).unwrap(),
        );
        assert!((a - b).abs().max() < 1e-12 * a.abs().max());
    }

    #[test]
    fn orthotropic_matrix_turned_by_ninety_degrees_swaps_its_axes() {
        let c = Matrix3::new(9.0, 2.0, 0.0, 2.0, 4.0, 0.0, 0.0, 0.0, 3.0);
        let r = rotate_plane(&c, std::f64::consts::FRAC_PI_2);
        let swapped = Matrix3::new(4.0, 2.0, 0.0, 2.0, 9.0, 0.0, 0.0, 0.0, 3.0);
        assert!((r - swapped).abs().max() < 1e-12, "{r}");
        let s = rotate_shear(
            &Matrix2::new(5.0, 0.0, 0.0, 1.0),
            std::f64::consts::FRAC_PI_2,
        );
        assert!(
            (s - Matrix2::new(1.0, 0.0, 0.0, 5.0)).abs().max() < 1e-12,
            "{s}"
        );
    }

    #[test]
    fn offset_shell_keeps_six_rigid_modes_and_its_mass_moves_rigidly() {
        let p = corners();
        let mut s = plate();
        let mut section = ShellSection::isotropic(&s.material, 0.002, 0.002);
        section.offset = 0.013;
        s.section = Some(Box::new(section));
        let k = stiffness(0, &s, &p).unwrap();
        let scale = k.abs().max();
        let eig = k.symmetric_eigenvalues();
        assert_eq!(eig.iter().filter(|v| v.abs() < 1e-9 * scale).count(), 6);
        assert!(eig.iter().all(|v| *v > -1e-9 * scale));
        // The mass sits on the plane offset by z0 n: its first moment, seen as the coupling of
        // a unit x translation with a rigid rotation ω, is m (ω × (c + z0 n))ₓ.
        let m = lumped_mass(0, &s, &p).unwrap();
        let geo = geometry(0, &p).unwrap();
        let n = geo.frame.row(2).transpose();
        let mass = s.material.density * s.thickness * geo.area;
        let mut translate = SMatrix::<f64, 24, 1>::zeros();
        for i in 0..4 {
            translate[6 * i] = 1.0;
        }
        let omega = Vector3::new(0.0, 1.0, 0.0);
        let mut rotate = SMatrix::<f64, 24, 1>::zeros();
        for (i, x) in p.iter().enumerate() {
            let v = omega.cross(x);
            for d in 0..3 {
                rotate[6 * i + d] = v[d];
                rotate[6 * i + 3 + d] = omega[d];
            }
        }
        // c: centroid of the corner masses on the grid plane.
        let c: Vector3<f64> = (0..4)
            .map(|i| p[i] * m[(6 * i, 6 * i)])
            .fold(Vector3::zeros(), |a, b| a + b)
            / mass;
        let expected = mass * omega.cross(&(c + n * 0.013))[0];
        let got = (translate.transpose() * m * rotate)[0];
        assert!((got - expected).abs() < 1e-12 * mass, "{got} vs {expected}");
    }

    #[test]
    fn offset_updates_equal_the_dense_transformation() {
        let k = stiffness(0, &plate(), &corners()).unwrap();
        let mut t = Mat24::identity();
        for i in 0..4 {
            t[(6 * i, 6 * i + 4)] = 0.01;
            t[(6 * i + 1, 6 * i + 3)] = -0.01;
        }
        let mut fast = k;
        apply_offset(&mut fast, 4, 0.01);
        let dense = t.transpose() * k * t;
        assert!((fast - dense).abs().max() < 1e-13 * dense.abs().max());
    }

    #[test]
    fn lumped_mass_sums_to_the_panel_mass() {
        let p = corners();
        let s = plate();
        let m = lumped_mass(0, &s, &p).unwrap();
        let geo = geometry(0, &p).unwrap();
        let total: f64 = (0..4).map(|i| m[(6 * i, 6 * i)]).sum();
        let expected = s.material.density * s.thickness * geo.area;
        assert!((total - expected).abs() < 1e-12 * expected);
    }

    #[test]
    fn bow_tie_quadrilateral_is_rejected_with_its_index() {
        let mut p = corners();
        p.swap(1, 2);
        let err = stiffness(42, &plate(), &p).unwrap_err();
        assert!(err.to_string().contains("shell 42"), "{err}");
    }
}
