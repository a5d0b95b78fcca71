//! Solids: CTETRA / CPENTA / CHEXA with their PSOLID and MAT1 → [`crate::fe::mesh::Solid`]s.

use std::collections::BTreeMap;

use super::super::cards::{Psolid, SolidElement};
use super::super::lexer::Loc;
use super::{mesh_error, NastranBody};
use crate::fe::elements::Entity;
use crate::fe::error::FeError;
use crate::fe::mesh::{Material, Solid};
use crate::fe::solid::check_geometry;

/// Adds the solid elements to `body`. `material(mid, line, user)` gives the isotropic material
/// of a MAT1 (density scaled by WTMASS), `system(cid, line, user)` checks that a coordinate
/// system exists.
pub(crate) fn add_solids(
    elements: &BTreeMap<u32, SolidElement>,
    properties: &BTreeMap<u32, Psolid>,
    material: &dyn Fn(u32, &Loc, &str) -> Result<Material, FeError>,
    system: &dyn Fn(u32, &Loc, &str) -> Result<(), FeError>,
    body: &mut NastranBody,
) -> Result<(), FeError> {
    let mut materials: BTreeMap<u32, Material> = BTreeMap::new();
    for (&id, e) in elements {
        let user = format!("{} {id}", e.card);
        let p = properties.get(&e.pid).ok_or_else(|| {
            mesh_error(
                &e.line,
                format!("{user}: property PSOLID {} not found", e.pid),
            )
        })?;
        let m = match materials.get(&p.id) {
            Some(m) => *m,
            None => {
                let owner = format!("PSOLID {}", p.id);
                if let Some(cid) = p.cordm {
                    system(cid, &p.line, &format!("{owner} CORDM"))?;
                }
                let m = material(p.mid, &p.line, &owner)?;
                materials.insert(p.id, m);
                m
            }
        };
        let nodes = e
            .grids
            .iter()
            .map(|g| {
                body.grid_index
                    .get(g)
                    .copied()
                    .ok_or_else(|| mesh_error(&e.line, format!("{user}: GRID {g} not found")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let x: Vec<_> = nodes.iter().map(|&k| body.mesh.nodes[k]).collect();
        check_geometry(&x).map_err(|why| mesh_error(&e.line, format!("{user}: {why}")))?;
        body.mesh.solids.push(Solid { nodes, material: m });
        body.element_ids.push(Entity::Solid, id);
    }
    Ok(())
}
