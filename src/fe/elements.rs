//! The registry of mesh entity kinds: each kind ([`Element`], implemented in its own file) with
//! its list in the [`Mesh`], once. Assembly, the mesh checks, the deck writer and the deck
//! reader's element ids go through [`Entity::ALL`] in this order, which is also the order in
//! which assembly sums contributions and the writer numbers elements.

use nalgebra::Vector3;

use super::element::{BulkWriter, CheckLimits, Element, ElementMatrices, Finding, LinkEquation};
use super::error::FeError;
use super::mesh::{
    Beam, Bush, GroundSpring, InterpolationLink, Mesh, PointMass, RigidLink, Shell, Solid, Spring,
    TriShell,
};

/// The elements of one kind in a mesh, asked by position: [`Element`] for a whole list, so that
/// the kinds can be looped over.
pub trait ElementList {
    /// How many there are.
    fn len(&self) -> usize;
    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The kind's name in messages about a mesh built in code ([`Element::NAME`]).
    fn name(&self) -> &'static str;
    /// [`Element::HOLDS`].
    fn holds(&self) -> bool;
    /// [`Element::nodes`] of element `i`.
    fn nodes(&self, i: usize) -> Vec<usize>;
    /// [`Element::grounds`] of element `i`.
    fn grounds(&self, i: usize) -> bool;
    /// [`Element::matrices`] of element `i`.
    fn matrices(&self, i: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError>;
    /// [`Element::equations`] of element `i`.
    fn equations(&self, i: usize, mesh: &Mesh) -> Result<Vec<LinkEquation>, FeError>;
    /// [`Element::check_shape`] of element `i`.
    fn check_shape(
        &self,
        i: usize,
        mesh: &Mesh,
        points: &[Vector3<f64>],
        limits: &CheckLimits,
    ) -> Vec<Finding>;
    /// [`Element::write_bulk`] of element `i`.
    fn write_bulk(&self, i: usize, mesh: &Mesh, deck: &mut dyn BulkWriter) -> Result<(), FeError>;
}

impl<E: Element> ElementList for Vec<E> {
    fn len(&self) -> usize {
        <[E]>::len(self)
    }
    fn name(&self) -> &'static str {
        E::NAME
    }
    fn holds(&self) -> bool {
        E::HOLDS
    }
    fn nodes(&self, i: usize) -> Vec<usize> {
        self[i].nodes()
    }
    fn grounds(&self, i: usize) -> bool {
        self[i].grounds()
    }
    fn matrices(&self, i: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        self[i].matrices(i, mesh)
    }
    fn equations(&self, i: usize, mesh: &Mesh) -> Result<Vec<LinkEquation>, FeError> {
        self[i].equations(i, mesh)
    }
    fn check_shape(
        &self,
        i: usize,
        mesh: &Mesh,
        points: &[Vector3<f64>],
        limits: &CheckLimits,
    ) -> Vec<Finding> {
        self[i].check_shape(i, mesh, points, limits)
    }
    fn write_bulk(&self, i: usize, mesh: &Mesh, deck: &mut dyn BulkWriter) -> Result<(), FeError> {
        self[i].write_bulk(i, mesh, deck)
    }
}

/// The registry: one line per kind, `Variant(Type) => mesh field`, generating [`Entity`] and
/// its way to the mesh's list.
macro_rules! registry {
    ($($(#[$doc:meta])* $kind:ident($ty:ty) => $field:ident,)*) => {
        /// Which kind of mesh entity (an element list of the [`Mesh`]) a message or an id
        /// names.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Entity {
            $($(#[$doc])* $kind,)*
        }

        impl Entity {
            /// Every kind, in the registry's order.
            pub const ALL: &'static [Entity] = &[$(Entity::$kind),*];

            /// The entity's name in a mesh built in code (`shell`, `ground spring`, …).
            pub fn mesh_name(self) -> &'static str {
                match self {
                    $(Entity::$kind => <$ty as Element>::NAME,)*
                }
            }

            /// The mesh's elements of this kind.
            pub fn of(self, mesh: &Mesh) -> &dyn ElementList {
                match self {
                    $(Entity::$kind => &mesh.$field,)*
                }
            }
        }
    };
}

registry! {
    /// `mesh.beams[i]`.
    Beam(Beam) => beams,
    /// `mesh.shells[i]`.
    Shell(Shell) => shells,
    /// `mesh.triangles[i]`.
    Triangle(TriShell) => triangles,
    /// `mesh.masses[i]`.
    Mass(PointMass) => masses,
    /// `mesh.ground_springs[i]`.
    GroundSpring(GroundSpring) => ground_springs,
    /// `mesh.springs[i]`.
    Spring(Spring) => springs,
    /// `mesh.bushes[i]`.
    Bush(Bush) => bushes,
    /// `mesh.solids[i]`.
    Solid(Solid) => solids,
    /// `mesh.rigid_links[i]`.
    RigidLink(RigidLink) => rigid_links,
    /// `mesh.interpolation_links[i]`.
    InterpolationLink(InterpolationLink) => interpolation_links,
}

/// Every entity of `mesh` as (kind, index, nodes), in the registry's order.
pub fn all_nodes(mesh: &Mesh) -> impl Iterator<Item = (Entity, usize, Vec<usize>)> + '_ {
    Entity::ALL.iter().flat_map(move |&kind| {
        let list = kind.of(mesh);
        (0..list.len()).map(move |i| (kind, i, list.nodes(i)))
    })
}
