//! What every kind of mesh entity answers, behind one trait: its nodes, its matrices or its
//! constraint equations, its shape checks and its bulk data cards. Assembly
//! ([`super::assembly`]), the mesh checks ([`super::checks`]) and the deck writer
//! ([`crate::nastran::write_bulk_deck`]) loop once over the registered kinds
//! ([`super::elements`]) and ask each element; what a kind is made of lives in its own file
//! (`beam.rs`, `shell.rs`, …), so a new kind is its file and one line of the registry.
//!
//! This module is the vocabulary the kinds and their users share (the trait, what an element
//! returns, the check limits, the card writer's interface); it imports no element kind.

use nalgebra::{DMatrix, Dim, Matrix, RawStorage, Vector3};

use super::error::FeError;
use super::mesh::{Material, Mesh};

/// One dependent DOF expressed through other DOFs (a link's constraint equation).
#[derive(Debug, Clone, PartialEq)]
pub struct LinkEquation {
    /// Dependent slot `node * 6 + dof`.
    pub dependent: usize,
    /// `(slot, coefficient)` terms; the referenced slots may themselves be dependent.
    pub terms: Vec<(usize, f64)>,
    /// The link that produced the equation, for error messages ("rigid link 3").
    pub origin: String,
}

/// What one element adds to the global matrices: stiffness, mass and viscous damping in global
/// axes on [`Element::nodes`] (six DOFs per node, in node order); `None` adds nothing.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ElementMatrices {
    /// Stiffness (N/m, N m/rad).
    pub k: Option<DMatrix<f64>>,
    /// Mass (kg, kg m²).
    pub m: Option<DMatrix<f64>>,
    /// Viscous damping (N s/m, N m s/rad).
    pub c: Option<DMatrix<f64>>,
}

impl ElementMatrices {
    /// Stiffness and mass.
    pub fn stiffness_and_mass<R1: Dim, C1: Dim, S1, R2: Dim, C2: Dim, S2>(
        k: &Matrix<f64, R1, C1, S1>,
        m: &Matrix<f64, R2, C2, S2>,
    ) -> Self
    where
        S1: RawStorage<f64, R1, C1>,
        S2: RawStorage<f64, R2, C2>,
    {
        Self {
            k: Some(dynamic(k)),
            m: Some(dynamic(m)),
            c: None,
        }
    }

    /// Stiffness and damping.
    pub fn stiffness_and_damping<R1: Dim, C1: Dim, S1, R2: Dim, C2: Dim, S2>(
        k: &Matrix<f64, R1, C1, S1>,
        c: &Matrix<f64, R2, C2, S2>,
    ) -> Self
    where
        S1: RawStorage<f64, R1, C1>,
        S2: RawStorage<f64, R2, C2>,
    {
        Self {
            k: Some(dynamic(k)),
            m: None,
            c: Some(dynamic(c)),
        }
    }
}

/// `m` as a matrix of dynamic size (the same values).
pub fn dynamic<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(m: &Matrix<f64, R, C, S>) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// What to do with elements whose shape is poor but whose matrices are still valid (warp,
/// taper, skew, Jacobian ratio beyond the limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoorShape {
    /// Refuse the mesh (a mesh built in code must be good).
    Refuse,
    /// Accept and report counted warnings, as Nastran's GEOMCHECK does by default.
    Warn,
}

/// Limits of the geometric checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckLimits {
    /// Largest corner offset from the mean plane / √area of a shell.
    pub max_warp: f64,
    /// Smallest ratio of corner Jacobians of a shell (1 = parallelogram, ≤ 0 = inverted).
    pub min_jacobian_ratio: f64,
    /// Largest taper of a CQUAD4: 1 − 2·(smallest corner triangle area)/(element area)
    /// (0 for a parallelogram, 1 when a corner collapses); `None`: not checked.
    pub max_taper: Option<f64>,
    /// Smallest angle (degrees) between the lines joining the midpoints of opposite sides of
    /// a CQUAD4 (90 for a rectangle); `None`: not checked.
    pub min_skew_angle_deg: Option<f64>,
    /// Smallest beam length (m).
    pub min_beam_length: f64,
    /// Smallest shell area (m²).
    pub min_shell_area: f64,
    /// Accept structures made of several parts that share no element.
    pub allow_disconnected_parts: bool,
    /// Poorly shaped but valid elements: refused or reported.
    pub poor_shape: PoorShape,
}

impl Default for CheckLimits {
    fn default() -> Self {
        Self {
            max_warp: 0.01,
            min_jacobian_ratio: 0.2,
            max_taper: None,
            min_skew_angle_deg: None,
            min_beam_length: 1e-6,
            min_shell_area: 1e-10,
            allow_disconnected_parts: false,
            poor_shape: PoorShape::Refuse,
        }
    }
}

impl CheckLimits {
    /// Limits for a body read from a user's Nastran deck: what makes an element's matrices
    /// wrong (zero or negative Jacobian or area, coincident corners, non-finite coordinates)
    /// is refused; poor shapes are warnings at Nastran's GEOMCHECK defaults (Q4_WARP 0.05,
    /// Q4_TAPER 0.5, Q4_SKEW 30°) and a corner Jacobian ratio below 0.2.
    pub fn nastran_deck() -> Self {
        Self {
            max_warp: 0.05,
            min_jacobian_ratio: 0.2,
            max_taper: Some(0.5),
            min_skew_angle_deg: Some(30.0),
            poor_shape: PoorShape::Warn,
            ..Self::default()
        }
    }
}

/// A shape test whose limit an element fails ([`CheckLimits`]): refused or counted as the
/// limits' [`PoorShape`] says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeTest {
    /// Warp ratio above [`CheckLimits::max_warp`].
    Warp,
    /// Corner Jacobian ratio below [`CheckLimits::min_jacobian_ratio`].
    JacobianRatio,
    /// Taper above [`CheckLimits::max_taper`] (counted only: never refused).
    Taper,
    /// Skew angle below [`CheckLimits::min_skew_angle_deg`] (counted only: never refused).
    Skew,
}

/// What a shape check found wrong with one element (the caller names the element).
#[derive(Debug, Clone, PartialEq)]
pub enum Finding {
    /// Its matrices would be wrong: refused, with why.
    Wrong(String),
    /// It names a node more than once.
    RepeatedNode,
    /// A shape test failed with this value.
    Poor(ShapeTest, f64),
}

/// A field of a bulk data card being written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Field {
    /// Blank.
    Blank,
    /// An integer.
    Int(u64),
    /// A real.
    Real(f64),
}

impl Field {
    /// The component digits (`123456`) of a DOF mask, as a field.
    pub fn components(mask: &[bool; 6]) -> Result<Field, FeError> {
        let digits = (0..6)
            .filter(|&d| mask[d])
            .fold(0u64, |acc, d| acc * 10 + d as u64 + 1);
        if digits == 0 {
            return Err(FeError::InvalidInput(
                "a link or support lists no components".into(),
            ));
        }
        Ok(Field::Int(digits))
    }
}

/// Where elements write themselves as bulk data ([`crate::nastran::write_bulk_deck`] is one):
/// element and GRID ids, materials and properties written once on first use, cards.
pub trait BulkWriter {
    /// The id of the next element (numbered from 1 in the order written).
    fn element_id(&mut self) -> Field;
    /// The GRID id of `node`, which `what` refers to (an error if the node does not exist).
    fn grid(&self, what: &str, node: usize) -> Result<Field, FeError>;
    /// The MAT1 id of `material`, written on first use.
    fn material(&mut self, material: &Material) -> Result<u64, FeError>;
    /// The id of the property `card` with `values` (its identity), written on first use as
    /// `card` with `fields(id)`.
    fn property(
        &mut self,
        card: &str,
        values: &[f64],
        fields: &dyn Fn(u64) -> Vec<Field>,
    ) -> Result<u64, FeError>;
    /// Writes the card `name` with `fields`.
    fn card(&mut self, name: &str, fields: &[Field]) -> Result<(), FeError>;
}

/// One kind of mesh entity: an element with matrices, a point mass, a spring, a link. Each kind
/// implements it in its own file and is listed once in [`super::elements`]; `index` is the
/// element's position in its list of the mesh (it names the element in messages as
/// `"{NAME} {index}"`).
pub trait Element {
    /// The kind's name in messages about a mesh built in code (`beam`, `ground spring`).
    const NAME: &'static str;
    /// Whether the element gives its nodes stiffness, holding them and joining them into one
    /// part (a point mass does not).
    const HOLDS: bool = true;

    /// The nodes it refers to, in its own order (the order of its matrices).
    fn nodes(&self) -> Vec<usize>;

    /// Whether it holds its nodes to ground (a spring or bush to ground), so that a part it
    /// belongs to is not loose.
    fn grounds(&self) -> bool {
        false
    }

    /// Its stiffness, mass and damping in global axes on [`Element::nodes`], checked.
    fn matrices(&self, _index: usize, _mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        Ok(ElementMatrices::default())
    }

    /// Its constraint equations (a link: eliminated exactly in assembly).
    fn equations(&self, _index: usize, _mesh: &Mesh) -> Result<Vec<LinkEquation>, FeError> {
        Ok(Vec::new())
    }

    /// What is wrong with its shape, given the positions of its nodes (in node order, all
    /// existing).
    fn check_shape(
        &self,
        _index: usize,
        _mesh: &Mesh,
        _points: &[Vector3<f64>],
        _limits: &CheckLimits,
    ) -> Vec<Finding> {
        Vec::new()
    }

    /// Writes it as bulk data cards (with its properties and materials on first use).
    fn write_bulk(
        &self,
        index: usize,
        mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError>;
}
