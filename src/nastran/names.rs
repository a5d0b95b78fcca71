//! Messages about a body read from a deck name the deck's own ids: `GRID 5000`,
//! `CQUAD4 1234 (line 12 of doors.bdf)`, never the mesh's internal indices.

use std::collections::BTreeMap;

use super::{ElementIds, Loc, NastranBody};
use crate::fe::checks::Naming;
use crate::fe::elements::Entity;

/// Names of a deck body's nodes and elements for [`crate::fe::checks`] and the reduction's
/// messages. Owns what it needs, so it outlives the body's mesh being moved on.
#[derive(Debug, Clone, Default)]
pub struct DeckNames {
    /// Node index → GRID id (`None`: a node the reader added, see `added`).
    grids: Vec<Option<u32>>,
    /// Names of nodes that are no GRID: the centres of gravity of offset masses.
    added: BTreeMap<usize, String>,
    /// Element ids per mesh entity kind, in mesh order.
    ids: ElementIds,
    /// Element id → (card, where).
    cards: BTreeMap<u32, (Loc, &'static str)>,
    /// GRID ids of the ends of each merged scalar spring/damper (ground: one).
    springs: Vec<Vec<u32>>,
    ground_springs: Vec<u32>,
}

impl DeckNames {
    /// The names of `body`'s nodes and elements.
    pub fn new(body: &NastranBody) -> Self {
        let mesh = &body.mesh;
        let mut grids = vec![None; mesh.nodes.len()];
        for (&g, &node) in &body.grid_index {
            if let Some(slot) = grids.get_mut(node) {
                *slot = Some(g);
            }
        }
        let e = &body.element_ids;
        let mut names = Self {
            grids,
            added: BTreeMap::new(),
            ids: e.clone(),
            cards: body.element_cards.clone(),
            springs: Vec::new(),
            ground_springs: Vec::new(),
        };
        // An offset CONM2/CONM1 puts its mass on a node of its own, carried by a rigid link
        // that bears the mass's id.
        for (i, link) in mesh.rigid_links.iter().enumerate() {
            let Some(&id) = e.of(Entity::RigidLink).get(i) else {
                continue;
            };
            if let Some((_, card @ ("CONM2" | "CONM1"))) = body.element_cards.get(&id) {
                for &node in &link.dependent {
                    names
                        .added
                        .insert(node, format!("the centre of gravity of {card} {id}"));
                }
            }
        }
        names.springs = mesh
            .springs
            .iter()
            .map(|s| s.nodes.iter().filter_map(|&k| names.grid(k)).collect())
            .collect();
        names.ground_springs = mesh
            .ground_springs
            .iter()
            .filter_map(|s| names.grid(s.node))
            .collect();
        names
    }

    /// GRID id of node `node`, if it is a GRID.
    pub fn grid(&self, node: usize) -> Option<u32> {
        self.grids.get(node).copied().flatten()
    }

    /// `CQUAD4 1234 (line 12 of doors.bdf)` for element id `id`.
    pub fn element(&self, id: u32) -> String {
        match self.cards.get(&id) {
            Some((loc, card)) => format!("{card} {id} (line {loc})"),
            None => format!("element {id}"),
        }
    }
}

impl Naming for DeckNames {
    fn node(&self, node: usize) -> String {
        match (self.grid(node), self.added.get(&node)) {
            (Some(g), _) => format!("GRID {g}"),
            (None, Some(name)) => name.clone(),
            (None, None) => format!("node {node} (no GRID)"),
        }
    }

    fn entity(&self, kind: Entity, index: usize) -> String {
        let grids = |list: &[u32]| {
            list.iter()
                .map(|g| g.to_string())
                .collect::<Vec<_>>()
                .join(" and GRID ")
        };
        match kind {
            Entity::Spring => match self.springs.get(index) {
                Some(ends) => format!("the CELAS/CDAMP cards between GRID {}", grids(ends)),
                None => format!("spring {index}"),
            },
            Entity::GroundSpring => match self.ground_springs.get(index) {
                Some(g) => format!("the CELAS/CDAMP cards from GRID {g} to ground"),
                None => format!("ground spring {index}"),
            },
            _ => match self.ids.of(kind).get(index) {
                Some(&id) => self.element(id),
                None => format!("{} {index}", kind.mesh_name()),
            },
        }
    }
}
