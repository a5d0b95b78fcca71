//! Isoparametric solid elements with translational DOFs only: linear tetrahedron (4 nodes,
//! constant strain), quadratic tetrahedron (10 nodes), linear wedge (6 nodes) and trilinear
//! hexahedron (8 nodes, with incompatible modes), all with consistent mass.
//!
//! Node order is Nastran's: CTETRA G1..G4 corners, G5..G10 mid-edge on 1-2, 2-3, 3-1, 1-4,
//! 2-4, 3-4; CPENTA G1..G3 one triangle, G4..G6 the opposite one with G4 over G1; CHEXA G1..G4
//! one quadrilateral face, G5..G8 the opposite one with G5 over G1. Either handedness of the
//! numbering is accepted (as Nastran does): a uniformly negative Jacobian is a mirrored
//! numbering of a valid element; a Jacobian that vanishes or changes sign inside the element
//! (at a corner, mid-edge node or integration point) is an inverted or degenerate element.
//!
//! Integration: tetrahedra stiffness on the 4-point rule (degree 2: exact for straight-edged
//! 10-node tetrahedra), mass on a 14-point degree-5 rule (exact consistent mass of the
//! 10-node tetrahedron); wedge stiffness on 3 triangle points × 2 Gauss points, mass on 6 × 3
//! (degree 4 × 5); hexahedron stiffness on 2 × 2 × 2 Gauss points, mass on 3 × 3 × 3.
//!
//! The hexahedron adds the three bubble modes 1 − ξ², 1 − η², 1 − ζ² per displacement component
//! (Wilson's incompatible modes) with Taylor's correction (their derivatives taken with the
//! Jacobian at the centre, scaled by det J₀ / det J), condensed statically: bending of a
//! rectangular element is exact, so the element does not shear-lock (this plays the role of
//! Nastran's bubble functions), and the correction makes it pass the constant-strain patch
//! test on any distorted mesh. The linear tetrahedron and the wedge have no such enhancement:
//! the tetrahedron locks in bending (use 10-node tetrahedra or fine meshes where bending
//! matters); the wedge bends like a hexahedron without incompatible modes through its
//! thickness direction, adequate as a filler in hexahedral meshes.
//!
//! Nodes of solids carry no rotational stiffness: assembly removes the rotations of nodes that
//! receive no rotational stiffness from anything (`remove_free_rotations`), as Nastran's
//! AUTOSPC does.

use faer::sparse::Triplet;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Vector3};

use super::dof::{DofMap, DOF_PER_NODE};
use super::element::LinkEquation;
use super::element::{BulkWriter, CheckLimits, Element, ElementMatrices, Field, Finding};
use super::error::FeError;
use super::mesh::{Material, Mesh, Solid};

/// The element formulations, chosen by the number of nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolidKind {
    /// Four-node tetrahedron (CTETRA), constant strain.
    Tetra4,
    /// Ten-node tetrahedron (CTETRA with mid-edge nodes).
    Tetra10,
    /// Six-node wedge (CPENTA).
    Penta6,
    /// Eight-node hexahedron (CHEXA) with incompatible modes.
    Hexa8,
}

impl SolidKind {
    /// The formulation for `n` nodes (4, 6, 8 or 10).
    pub fn from_node_count(n: usize) -> Option<Self> {
        match n {
            4 => Some(Self::Tetra4),
            10 => Some(Self::Tetra10),
            6 => Some(Self::Penta6),
            8 => Some(Self::Hexa8),
            _ => None,
        }
    }

    /// Number of nodes.
    pub fn n_nodes(self) -> usize {
        match self {
            Self::Tetra4 => 4,
            Self::Tetra10 => 10,
            Self::Penta6 => 6,
            Self::Hexa8 => 8,
        }
    }

    /// The Nastran card of this element.
    pub fn card(self) -> &'static str {
        match self {
            Self::Tetra4 | Self::Tetra10 => "CTETRA",
            Self::Penta6 => "CPENTA",
            Self::Hexa8 => "CHEXA",
        }
    }
}

const HEXA_CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Mid-edge nodes 5..10 of the ten-node tetrahedron: the corners (0-based) of their edges.
const TETRA_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];

/// Shape functions and their derivatives with respect to the natural coordinates.
struct Shape {
    n: Vec<f64>,
    dn: Vec<Vector3<f64>>,
}

/// Volume coordinates L1..L4 of the tetrahedron at natural point (r, s, t) and their
/// (constant) gradients.
fn tetra_coordinates(p: [f64; 3]) -> ([f64; 4], [Vector3<f64>; 4]) {
    (
        [1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]],
        [
            Vector3::new(-1.0, -1.0, -1.0),
            Vector3::x(),
            Vector3::y(),
            Vector3::z(),
        ],
    )
}

fn shape(kind: SolidKind, p: [f64; 3]) -> Shape {
    match kind {
        SolidKind::Tetra4 => {
            let (l, dl) = tetra_coordinates(p);
            Shape {
                n: l.to_vec(),
                dn: dl.to_vec(),
            }
        }
        SolidKind::Tetra10 => {
            let (l, dl) = tetra_coordinates(p);
            let mut n = Vec::with_capacity(10);
            let mut dn = Vec::with_capacity(10);
            for i in 0..4 {
                n.push(l[i] * (2.0 * l[i] - 1.0));
                dn.push(dl[i] * (4.0 * l[i] - 1.0));
            }
            for [i, j] in TETRA_EDGES {
                n.push(4.0 * l[i] * l[j]);
                dn.push((dl[i] * l[j] + dl[j] * l[i]) * 4.0);
            }
            Shape { n, dn }
        }
        SolidKind::Penta6 => {
            let l = [1.0 - p[0] - p[1], p[0], p[1]];
            let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
            let mut n = vec![0.0; 6];
            let mut dn = vec![Vector3::zeros(); 6];
            for (side, sign) in [(0, -1.0), (3, 1.0)] {
                let h = 0.5 * (1.0 + sign * p[2]);
                for i in 0..3 {
                    n[side + i] = l[i] * h;
                    dn[side + i] = Vector3::new(dl[i][0] * h, dl[i][1] * h, 0.5 * sign * l[i]);
                }
            }
            Shape { n, dn }
        }
        SolidKind::Hexa8 => {
            let mut n = Vec::with_capacity(8);
            let mut dn = Vec::with_capacity(8);
            for c in HEXA_CORNERS {
                let f = [1.0 + c[0] * p[0], 1.0 + c[1] * p[1], 1.0 + c[2] * p[2]];
                n.push(0.125 * f[0] * f[1] * f[2]);
                dn.push(Vector3::new(
                    0.125 * c[0] * f[1] * f[2],
                    0.125 * c[1] * f[0] * f[2],
                    0.125 * c[2] * f[0] * f[1],
                ));
            }
            Shape { n, dn }
        }
    }
}

/// Stiffness on the nodal DOFs K_uu, coupling K_ua and K_aa of the incompatible modes.
type StiffnessParts = (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>);

/// Assembly triplets of K, M and C.
type Triplets = [Vec<Triplet<usize, usize, f64>>; 3];

/// An integration rule: natural points and weights.
type Rule = Vec<([f64; 3], f64)>;

fn gauss(n: usize) -> Vec<(f64, f64)> {
    match n {
        2 => {
            let a = 1.0 / 3f64.sqrt();
            vec![(-a, 1.0), (a, 1.0)]
        }
        _ => {
            let a = 0.6f64.sqrt();
            vec![(-a, 5.0 / 9.0), (0.0, 8.0 / 9.0), (a, 5.0 / 9.0)]
        }
    }
}

/// Points of a tetrahedron rule given by barycentric orbits: each `(l, w)` is one point with
/// barycentric coordinates `l` (L1..L4) and weight `w` (reference volume 1/6).
fn tetra_points(orbits: &[([f64; 4], f64)]) -> Rule {
    orbits
        .iter()
        .map(|(l, w)| ([l[1], l[2], l[3]], *w))
        .collect()
}

/// All distinct permutations of a barycentric tuple.
fn permutations(l: [f64; 4], w: f64) -> Vec<([f64; 4], f64)> {
    let mut out: Vec<([f64; 4], f64)> = Vec::new();
    let idx = [0usize, 1, 2, 3];
    for a in idx {
        for b in idx {
            for c in idx {
                for d in idx {
                    let perm = [a, b, c, d];
                    let mut seen = [false; 4];
                    if perm.iter().any(|&k| std::mem::replace(&mut seen[k], true)) {
                        continue;
                    }
                    let p = [l[a], l[b], l[c], l[d]];
                    if !out.iter().any(|(q, _)| q == &p) {
                        out.push((p, w));
                    }
                }
            }
        }
    }
    out
}

/// 4-point rule, exact to degree 2.
fn tetra_rule_4() -> Rule {
    let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
    tetra_points(&permutations([a, b, b, b], 1.0 / 24.0))
}

/// 14-point rule with positive weights, exact to degree 5 (Walkington 2000).
fn tetra_rule_14() -> Rule {
    let (a1, w1) = (0.092_735_250_310_891_2, 0.012_248_840_519_393_66);
    let (a2, w2) = (0.310_885_919_263_300_6, 0.018_781_320_953_002_64);
    let (b, w3) = (0.045_503_704_125_649_65, 0.007_091_003_462_846_911);
    let mut orbits = permutations([1.0 - 3.0 * a1, a1, a1, a1], w1);
    orbits.extend(permutations([1.0 - 3.0 * a2, a2, a2, a2], w2));
    orbits.extend(permutations([b, b, 0.5 - b, 0.5 - b], w3));
    tetra_points(&orbits)
}

/// Triangle rules on the reference triangle (area 1/2): degree 2 (3 points) or 4 (6 points).
fn triangle_rule(degree: usize) -> Vec<([f64; 2], f64)> {
    if degree <= 2 {
        let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
        vec![
            ([a, a], 1.0 / 6.0),
            ([b, a], 1.0 / 6.0),
            ([a, b], 1.0 / 6.0),
        ]
    } else {
        let mut out = Vec::new();
        for (a, w) in [
            (0.445_948_490_915_965, 0.223_381_589_678_011),
            (0.091_576_213_509_771, 0.109_951_743_655_322),
        ] {
            let b = 1.0 - 2.0 * a;
            for p in [[a, a], [b, a], [a, b]] {
                out.push((p, 0.5 * w));
            }
        }
        out
    }
}

fn penta_rule(triangle_degree: usize, line_points: usize) -> Rule {
    let mut out = Vec::new();
    for (p, wt) in triangle_rule(triangle_degree) {
        for (z, wz) in gauss(line_points) {
            out.push(([p[0], p[1], z], wt * wz));
        }
    }
    out
}

fn hexa_rule(n: usize) -> Rule {
    let g = gauss(n);
    let mut out = Vec::new();
    for &(x, wx) in &g {
        for &(y, wy) in &g {
            for &(z, wz) in &g {
                out.push(([x, y, z], wx * wy * wz));
            }
        }
    }
    out
}

/// Stiffness and mass rules of the tetrahedra, the wedge and the hexahedron, built once.
fn rules() -> &'static [(Rule, Rule); 3] {
    static RULES: std::sync::OnceLock<[(Rule, Rule); 3]> = std::sync::OnceLock::new();
    RULES.get_or_init(|| {
        [
            (tetra_rule_4(), tetra_rule_14()),
            (penta_rule(2, 2), penta_rule(4, 3)),
            (hexa_rule(2), hexa_rule(3)),
        ]
    })
}

fn rule_set(kind: SolidKind) -> &'static (Rule, Rule) {
    let r = rules();
    match kind {
        SolidKind::Tetra4 | SolidKind::Tetra10 => &r[0],
        SolidKind::Penta6 => &r[1],
        SolidKind::Hexa8 => &r[2],
    }
}

fn stiffness_rule(kind: SolidKind) -> &'static Rule {
    &rule_set(kind).0
}

fn mass_rule(kind: SolidKind) -> &'static Rule {
    &rule_set(kind).1
}

/// Natural coordinates of the nodes.
fn node_points(kind: SolidKind) -> Vec<[f64; 3]> {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    match kind {
        SolidKind::Tetra4 => corners.to_vec(),
        SolidKind::Tetra10 => {
            let mut out = corners.to_vec();
            for [i, j] in TETRA_EDGES {
                out.push([
                    0.5 * (corners[i][0] + corners[j][0]),
                    0.5 * (corners[i][1] + corners[j][1]),
                    0.5 * (corners[i][2] + corners[j][2]),
                ]);
            }
            out
        }
        SolidKind::Penta6 => vec![
            [0.0, 0.0, -1.0],
            [1.0, 0.0, -1.0],
            [0.0, 1.0, -1.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
        ],
        SolidKind::Hexa8 => HEXA_CORNERS.to_vec(),
    }
}

/// Centre of the reference element (where the hexahedron's incompatible modes take J₀).
fn centre(kind: SolidKind) -> [f64; 3] {
    match kind {
        SolidKind::Tetra4 | SolidKind::Tetra10 => [0.25; 3],
        SolidKind::Penta6 => [1.0 / 3.0, 1.0 / 3.0, 0.0],
        SolidKind::Hexa8 => [0.0; 3],
    }
}

/// J with `J[(i, j)] = ∂x_i/∂ξ_j`.
fn jacobian(s: &Shape, x: &[Vector3<f64>]) -> Matrix3<f64> {
    let mut j = Matrix3::zeros();
    for (xi, dn) in x.iter().zip(&s.dn) {
        j += xi * dn.transpose();
    }
    j
}

/// A checked element: its formulation and the orientation of its numbering (+1 or −1).
#[derive(Debug, Clone, Copy)]
struct Checked {
    kind: SolidKind,
    sign: f64,
}

/// Checks the geometry of a solid with nodes at `x` and returns its volume. The error text
/// (without the element's name) says what is wrong: wrong node count, repeated or non-finite
/// nodes, or a Jacobian that vanishes or changes sign (zero volume, inverted or folded
/// element, a mid-edge node too far off its edge).
pub fn check_geometry(x: &[Vector3<f64>]) -> Result<f64, String> {
    let c = classify(x)?;
    Ok(volume_of(c, x))
}

fn classify(x: &[Vector3<f64>]) -> Result<Checked, String> {
    let kind = SolidKind::from_node_count(x.len()).ok_or_else(|| {
        format!(
            "{} nodes; solids have 4 or 10 (tetrahedron), 6 (wedge) or 8 (hexahedron)",
            x.len()
        )
    })?;
    if x.iter().any(|p| p.iter().any(|c| !c.is_finite())) {
        return Err("a node has non-finite coordinates".into());
    }
    let size = x.iter().map(|p| (p - x[0]).norm()).fold(0.0f64, f64::max);
    let tol = 1e-9 * size.powi(3);
    let mut points = node_points(kind);
    points.extend(stiffness_rule(kind).iter().map(|(p, _)| *p));
    let dets: Vec<f64> = points
        .iter()
        .map(|&p| jacobian(&shape(kind, p), x).determinant())
        .collect();
    let sign = if jacobian(&shape(kind, centre(kind)), x).determinant() < 0.0 {
        -1.0
    } else {
        1.0
    };
    let worst = dets.iter().map(|d| d * sign).fold(f64::INFINITY, f64::min);
    if worst.is_nan() || worst <= tol {
        let (lo, hi) = dets
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &d| {
                (lo.min(d), hi.max(d))
            });
        return Err(format!(
            "zero volume, inverted or folded element: the Jacobian determinant ranges over \
             [{lo:.3e}, {hi:.3e}] at the nodes and integration points (it must keep one sign \
             and stay away from zero; check the node order and positions)"
        ));
    }
    Ok(Checked { kind, sign })
}

fn volume_of(c: Checked, x: &[Vector3<f64>]) -> f64 {
    mass_rule(c.kind)
        .iter()
        .map(|&(p, w)| w * c.sign * jacobian(&shape(c.kind, p), x).determinant())
        .sum()
}

/// Isotropic elasticity matrix, Voigt order xx, yy, zz, xy, yz, zx (engineering shears).
pub fn elasticity(m: &Material) -> Matrix6<f64> {
    let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let g = e / (2.0 * (1.0 + nu));
    let mut d = Matrix6::zeros();
    for i in 0..3 {
        for j in 0..3 {
            d[(i, j)] = lambda;
        }
        d[(i, i)] = lambda + 2.0 * g;
        d[(i + 3, i + 3)] = g;
    }
    d
}

/// Strain-displacement rows for one function with gradient `g`, in columns `col..col + 3`.
fn put_b(b: &mut DMatrix<f64>, col: usize, g: &Vector3<f64>) {
    b[(0, col)] = g.x;
    b[(1, col + 1)] = g.y;
    b[(2, col + 2)] = g.z;
    b[(3, col)] = g.y;
    b[(3, col + 1)] = g.x;
    b[(4, col + 1)] = g.z;
    b[(4, col + 2)] = g.y;
    b[(5, col)] = g.z;
    b[(5, col + 2)] = g.x;
}

/// At one stiffness integration point: B of the nodal DOFs, B of the incompatible modes
/// (hexahedron only, else empty) and the weight w·|det J|.
fn b_matrices(
    c: Checked,
    x: &[Vector3<f64>],
    p: [f64; 3],
    w: f64,
    j0: &Option<(Matrix3<f64>, f64)>,
) -> Result<(DMatrix<f64>, DMatrix<f64>, f64), String> {
    let s = shape(c.kind, p);
    let j = jacobian(&s, x);
    let det = j.determinant();
    let jit = j
        .try_inverse()
        .ok_or("singular Jacobian at an integration point")?
        .transpose();
    let n = s.n.len();
    let mut b = DMatrix::zeros(6, 3 * n);
    for (k, dn) in s.dn.iter().enumerate() {
        put_b(&mut b, 3 * k, &(jit * dn));
    }
    let mut ba = DMatrix::zeros(6, 0);
    if let Some((j0it, det0)) = j0 {
        ba = DMatrix::zeros(6, 9);
        let scale = det0 / det;
        for a in 0..3 {
            let mut dp = Vector3::zeros();
            dp[a] = -2.0 * p[a];
            put_b(&mut ba, 3 * a, &(j0it * dp * scale));
        }
    }
    Ok((b, ba, w * c.sign * det))
}

/// J₀⁻ᵀ and det J₀ at the centre for the hexahedron's incompatible modes.
fn centre_jacobian(c: Checked, x: &[Vector3<f64>]) -> Result<Option<(Matrix3<f64>, f64)>, String> {
    if c.kind != SolidKind::Hexa8 {
        return Ok(None);
    }
    let j0 = jacobian(&shape(c.kind, centre(c.kind)), x);
    let inv = j0.try_inverse().ok_or("singular Jacobian at the centre")?;
    Ok(Some((inv.transpose(), j0.determinant())))
}

/// Stiffness on the nodal DOFs and, for the hexahedron, the pieces of the condensation
/// (K_ua, K_aa).
fn stiffness_parts(c: Checked, m: &Material, x: &[Vector3<f64>]) -> Result<StiffnessParts, String> {
    let d = DMatrix::from_iterator(6, 6, elasticity(m).iter().copied());
    let j0 = centre_jacobian(c, x)?;
    let nd = 3 * x.len();
    let na = if j0.is_some() { 9 } else { 0 };
    let mut kuu = DMatrix::zeros(nd, nd);
    let mut kua = DMatrix::zeros(nd, na);
    let mut kaa = DMatrix::zeros(na, na);
    for &(p, w) in stiffness_rule(c.kind) {
        let (b, ba, dv) = b_matrices(c, x, p, w, &j0)?;
        let db = &d * &b;
        kuu.gemm_tr(dv, &b, &db, 1.0);
        if na > 0 {
            let dba = &d * &ba;
            kua.gemm_tr(dv, &b, &dba, 1.0);
            kaa.gemm_tr(dv, &ba, &dba, 1.0);
        }
    }
    Ok((kuu, kua, kaa))
}

fn material_check(index: usize, m: &Material) -> Result<(), FeError> {
    let ok = m.youngs_modulus.is_finite()
        && m.youngs_modulus > 0.0
        && m.poisson_ratio > -1.0
        && m.poisson_ratio < 0.5
        && m.density.is_finite()
        && m.density >= 0.0;
    if ok {
        Ok(())
    } else {
        Err(FeError::InvalidInput(format!(
            "solid {index}: material E = {}, ν = {}, ρ = {} (need E > 0, −1 < ν < 0.5, ρ ≥ 0)",
            m.youngs_modulus, m.poisson_ratio, m.density
        )))
    }
}

fn checked(index: usize, solid: &Solid, x: &[Vector3<f64>]) -> Result<Checked, FeError> {
    material_check(index, &solid.material)?;
    if x.len() != solid.nodes.len() {
        return Err(FeError::InvalidInput(format!(
            "solid {index}: {} node positions for {} nodes",
            x.len(),
            solid.nodes.len()
        )));
    }
    classify(x).map_err(|why| FeError::Mesh(format!("solid {index}: {why}")))
}

/// Stiffness matrix (3n × 3n, DOFs ux uy uz per node in the element's node order) of a solid
/// with nodes at `x`; the hexahedron's incompatible modes are condensed out.
pub fn stiffness(index: usize, solid: &Solid, x: &[Vector3<f64>]) -> Result<DMatrix<f64>, FeError> {
    stiffness_checked(index, checked(index, solid, x)?, solid, x)
}

fn stiffness_checked(
    index: usize,
    c: Checked,
    solid: &Solid,
    x: &[Vector3<f64>],
) -> Result<DMatrix<f64>, FeError> {
    let fail = |why: String| FeError::Mesh(format!("solid {index}: {why}"));
    let (kuu, kua, kaa) = stiffness_parts(c, &solid.material, x).map_err(fail)?;
    if kaa.nrows() == 0 {
        return Ok(kuu);
    }
    let chol = kaa
        .cholesky()
        .ok_or_else(|| fail("singular incompatible-mode stiffness".into()))?;
    let k = &kuu - &kua * chol.solve(&kua.transpose());
    // Symmetric to round-off; make it exactly so for the sparse Cholesky downstream.
    Ok((&k + k.transpose()) * 0.5)
}

/// Consistent mass matrix ρ ∫ Nᵀ N dV (3n × 3n, as [`stiffness`]).
pub fn mass(index: usize, solid: &Solid, x: &[Vector3<f64>]) -> Result<DMatrix<f64>, FeError> {
    Ok(mass_checked(checked(index, solid, x)?, solid, x))
}

fn mass_checked(c: Checked, solid: &Solid, x: &[Vector3<f64>]) -> DMatrix<f64> {
    let n = x.len();
    let mut scalar = DMatrix::zeros(n, n);
    for &(p, w) in mass_rule(c.kind) {
        let s = shape(c.kind, p);
        let dv = w * c.sign * jacobian(&s, x).determinant();
        let nv = DVector::from_column_slice(&s.n);
        scalar.ger(dv, &nv, &nv, 1.0);
    }
    let rho = solid.material.density;
    let mut m = DMatrix::zeros(3 * n, 3 * n);
    for a in 0..n {
        for b in 0..n {
            for d in 0..3 {
                m[(3 * a + d, 3 * b + d)] = rho * scalar[(a, b)];
            }
        }
    }
    m
}

/// Volume of a solid (m³).
pub fn volume(index: usize, solid: &Solid, x: &[Vector3<f64>]) -> Result<f64, FeError> {
    let c = checked(index, solid, x)?;
    Ok(volume_of(c, x))
}

/// Strains (Voigt order of [`elasticity`], engineering shears) at the stiffness integration
/// points for nodal displacements `u` (the hexahedron's condensed incompatible modes
/// included).
pub fn strains(
    index: usize,
    solid: &Solid,
    x: &[Vector3<f64>],
    u: &[Vector3<f64>],
) -> Result<Vec<[f64; 6]>, FeError> {
    let c = checked(index, solid, x)?;
    let fail = |why: String| FeError::Mesh(format!("solid {index}: {why}"));
    if u.len() != x.len() {
        return Err(fail(format!(
            "{} displacements for {} nodes",
            u.len(),
            x.len()
        )));
    }
    let ue = DVector::from_iterator(3 * u.len(), u.iter().flat_map(|v| v.iter().copied()));
    let (_, kua, kaa) = stiffness_parts(c, &solid.material, x).map_err(fail)?;
    let alpha = if kaa.nrows() > 0 {
        let chol = kaa
            .cholesky()
            .ok_or_else(|| fail("singular incompatible-mode stiffness".into()))?;
        -chol.solve(&(kua.transpose() * &ue))
    } else {
        DVector::zeros(0)
    };
    let j0 = centre_jacobian(c, x).map_err(fail)?;
    let mut out = Vec::new();
    for &(p, w) in stiffness_rule(c.kind) {
        let (b, ba, _) = b_matrices(c, x, p, w, &j0).map_err(fail)?;
        let e = b * &ue + ba * &alpha;
        out.push([e[0], e[1], e[2], e[3], e[4], e[5]]);
    }
    Ok(out)
}

/// A 3n × 3n translational matrix spread onto 6 DOFs per node (rotations left empty).
fn six_dof(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows() / 3;
    let mut out = DMatrix::zeros(DOF_PER_NODE * n, DOF_PER_NODE * n);
    for a in 0..n {
        for b in 0..n {
            for i in 0..3 {
                for j in 0..3 {
                    out[(DOF_PER_NODE * a + i, DOF_PER_NODE * b + j)] = m[(3 * a + i, 3 * b + j)];
                }
            }
        }
    }
    out
}

/// Stiffness and mass of mesh solid `index` on 6 DOFs per node, for assembly.
pub(crate) fn assembly_matrices(
    mesh: &Mesh,
    index: usize,
) -> Result<(DMatrix<f64>, DMatrix<f64>), FeError> {
    let solid = &mesh.solids[index];
    let what = format!("solid {index}");
    let x = solid
        .nodes
        .iter()
        .map(|&k| mesh.position(&what, k))
        .collect::<Result<Vec<_>, _>>()?;
    let c = checked(index, solid, &x)?;
    Ok((
        six_dof(&stiffness_checked(index, c, solid, &x)?),
        six_dof(&mass_checked(c, solid, &x)),
    ))
}

/// Removes from the assembled triplets `[K, M, C]` the rotational DOFs of nodes carrying a
/// solid that received no stiffness at all (zero K diagonal: K is positive semi-definite, so
/// the whole row is zero), by constraining them, as Nastran's AUTOSPC does. Rotary inertia or
/// damping on such a DOF (a CONM2 on a solid grid) is dropped with it, as in Nastran. Returns
/// the numbering with these DOFs constrained and the triplets renumbered.
pub(crate) fn remove_free_rotations(
    mesh: &Mesh,
    dofs: DofMap,
    links: &[LinkEquation],
    triplets: Triplets,
) -> Result<(DofMap, Triplets), FeError> {
    if mesh.solids.is_empty() {
        return Ok((dofs, triplets));
    }
    let mut on_solid = vec![false; mesh.nodes.len()];
    for s in &mesh.solids {
        for &k in &s.nodes {
            if let Some(f) = on_solid.get_mut(k) {
                *f = true;
            }
        }
    }
    let owners = dofs.owners();
    let mut diagonal = vec![0.0; owners.len()];
    for t in &triplets[0] {
        if t.row == t.col {
            diagonal[t.row] += t.val;
        }
    }
    let extra: Vec<(usize, usize)> = owners
        .iter()
        .zip(&diagonal)
        .filter(|(&(node, d), &k)| d >= 3 && on_solid[node] && k == 0.0)
        .map(|(&owner, _)| owner)
        .collect();
    if extra.is_empty() {
        return Ok((dofs, triplets));
    }
    let mut constrained = mesh.constraints.clone();
    constrained.extend(&extra);
    let reduced = DofMap::with_frames(
        mesh.nodes.len(),
        &constrained,
        links,
        &mesh.displacement_frames,
    )?;
    let new_index: Vec<Option<usize>> = owners
        .iter()
        .map(|&(node, d)| reduced.global(node, d))
        .collect();
    let renumber = |list: Vec<Triplet<usize, usize, f64>>| {
        list.into_iter()
            .filter_map(|t| match (new_index[t.row], new_index[t.col]) {
                (Some(i), Some(j)) => Some(Triplet::new(i, j, t.val)),
                _ => None,
            })
            .collect()
    };
    let [k, m, c] = triplets;
    Ok((reduced, [renumber(k), renumber(m), renumber(c)]))
}

impl Element for Solid {
    const NAME: &'static str = "solid";

    fn nodes(&self) -> Vec<usize> {
        self.nodes.clone()
    }

    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        let (k, m) = assembly_matrices(mesh, index)?;
        Ok(ElementMatrices {
            k: Some(k),
            m: Some(m),
            c: None,
        })
    }

    fn check_shape(
        &self,
        _index: usize,
        _mesh: &Mesh,
        points: &[Vector3<f64>],
        _limits: &CheckLimits,
    ) -> Vec<Finding> {
        match check_geometry(points) {
            Err(why) => vec![Finding::Wrong(why)],
            Ok(_) => Vec::new(),
        }
    }

    /// CTETRA / CPENTA / CHEXA with a PSOLID per material (IN, ISOP, FCTN blank: the defaults).
    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let what = format!("solid {index}");
        let kind = SolidKind::from_node_count(self.nodes.len()).ok_or_else(|| {
            FeError::Mesh(format!(
                "{what}: {} nodes (4, 6, 8 or 10)",
                self.nodes.len()
            ))
        })?;
        let mid = deck.material(&self.material)?;
        let pid = deck.property("PSOLID", &[mid as f64], &|pid| {
            vec![Field::Int(pid), Field::Int(mid)]
        })?;
        let mut fields = vec![deck.element_id(), Field::Int(pid)];
        for &n in &self.nodes {
            fields.push(deck.grid(&what, n)?);
        }
        deck.card(kind.card(), &fields)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn factorial(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    #[test]
    fn tetrahedron_rules_integrate_monomials_exactly() {
        // ∫ r^a s^b t^c over the reference tetrahedron = a! b! c! / (a + b + c + 3)!.
        for (rule, degree) in [(tetra_rule_4(), 2), (tetra_rule_14(), 5)] {
            for a in 0..=degree {
                for b in 0..=degree - a {
                    for c in 0..=degree - a - b {
                        let exact =
                            factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
                        let q: f64 = rule
                            .iter()
                            .map(|(p, w)| {
                                w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)
                            })
                            .sum();
                        assert!((q - exact).abs() < 1e-14, "{a} {b} {c}: {q} vs {exact}");
                    }
                }
            }
        }
    }

    #[test]
    fn triangle_rules_integrate_monomials_exactly() {
        // ∫ r^a s^b over the reference triangle = a! b! / (a + b + 2)!.
        for degree in [2u32, 4] {
            let rule = triangle_rule(degree as usize);
            for a in 0..=degree {
                for b in 0..=degree - a {
                    let exact = factorial(a) * factorial(b) / factorial(a + b + 2);
                    let q: f64 = rule
                        .iter()
                        .map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32))
                        .sum();
                    assert!((q - exact).abs() < 1e-12, "{a} {b}: {q} vs {exact}");
                }
            }
        }
    }

    #[test]
    fn shape_functions_are_a_partition_of_unity_with_kronecker_nodes() {
        for kind in [
            SolidKind::Tetra4,
            SolidKind::Tetra10,
            SolidKind::Penta6,
            SolidKind::Hexa8,
        ] {
            let nodes = node_points(kind);
            for (i, &p) in nodes.iter().enumerate() {
                let s = shape(kind, p);
                for (j, v) in s.n.iter().enumerate() {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-14, "{kind:?} node {i} N{j} = {v}");
                }
            }
            // Derivatives against central differences at an interior point.
            let p = [0.21, 0.17, 0.13];
            let s = shape(kind, p);
            assert!((s.n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for d in 0..3 {
                let h = 1e-6;
                let (mut a, mut b) = (p, p);
                a[d] += h;
                b[d] -= h;
                let (sa, sb) = (shape(kind, a), shape(kind, b));
                for k in 0..s.n.len() {
                    let fd = (sa.n[k] - sb.n[k]) / (2.0 * h);
                    assert!((fd - s.dn[k][d]).abs() < 1e-8, "{kind:?} dN{k}/d{d}");
                }
            }
        }
    }
}
