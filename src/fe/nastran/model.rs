//! Cards → [`Mesh`]: grids in their coordinate systems, shells, bars and beams with their
//! properties and materials, concentrated masses, springs, dampers and single-point constraints.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Vector3};

use super::lexer::Card;
use crate::fe::mesh::{Beam, BeamSection, GroundSpring, Material, Mesh, PointMass, Shell, Spring};
use crate::fe::FeError;

/// Solution-control cards that may stand in a bulk section; they describe no structure.
const IGNORED: [&str; 3] = ["PARAM", "EIGRL", "EIGR"];

/// The body a deck describes: its mesh, and which node each GRID became.
#[derive(Debug, Clone, PartialEq)]
pub struct NastranBody {
    pub mesh: Mesh,
    /// GRID id → node index of [`NastranBody::mesh`].
    pub grid_index: BTreeMap<u32, usize>,
}

impl NastranBody {
    /// The node of GRID `id`.
    pub fn node(&self, id: u32) -> Result<usize, FeError> {
        self.grid_index
            .get(&id)
            .copied()
            .ok_or_else(|| FeError::InvalidInput(format!("the deck has no GRID {id}")))
    }
}

/// A rectangular coordinate system: origin and axes (columns) in the basic system.
#[derive(Debug, Clone, Copy)]
struct Frame {
    origin: Vector3<f64>,
    axes: Matrix3<f64>,
}

fn id(card: &Card, field: usize) -> Result<u32, FeError> {
    let v = card.int(field, None)?;
    u32::try_from(v)
        .ok()
        .filter(|v| *v > 0)
        .ok_or_else(|| card.invalid(&format!("field {}: id {v} must be positive", field + 2)))
}

fn by_id<'a, T>(
    map: &'a BTreeMap<u32, T>,
    key: u32,
    what: &str,
    card: &Card,
) -> Result<&'a T, FeError> {
    map.get(&key).ok_or_else(|| {
        card.invalid(&format!(
            "refers to {what} {key}, which the deck does not define"
        ))
    })
}

/// Component digits (`123456` style) → local DOF indices 0..5.
fn components(card: &Card, field: usize) -> Result<Vec<usize>, FeError> {
    let text = card.text(field);
    let mut out = Vec::new();
    for ch in text.chars() {
        match ch.to_digit(10) {
            Some(d @ 1..=6) => out.push(d as usize - 1),
            Some(0) if text.len() == 1 => {}
            _ => {
                return Err(card.invalid(&format!(
                    "field {}: \"{text}\" is not a list of components 1-6",
                    field + 2
                )))
            }
        }
    }
    Ok(out)
}

struct Pshell {
    material: u32,
    thickness: f64,
    bending_ratio: f64,
    nsm: f64,
}

struct Pbar {
    material: u32,
    section: BeamSection,
    nsm: f64,
}

/// A PBAR or (constant-section) PBEAM: MID, A, I1, I2 in fields 3 to 6 of both; J and NSM
/// where the card has them. Nastran's plane 1 holds the axis and the orientation vector (our
/// local y): I1 resists bending in it (our `iz`), I2 in plane 2 (our `iy`).
fn bar_property(c: &Card, j_field: usize, nsm_field: usize) -> Result<Pbar, FeError> {
    Ok(Pbar {
        material: id(c, 1)?,
        section: BeamSection {
            area: c.real(2, None)?,
            iz: c.real(3, None)?,
            iy: c.real(4, None)?,
            j: c.real(j_field, Some(0.0))?,
        },
        nsm: c.real(nsm_field, Some(0.0))?,
    })
}

/// Builds the body from the deck's cards.
pub fn build(cards: &[Card]) -> Result<NastranBody, FeError> {
    // First pass: coordinate systems, materials and properties.
    let mut frames: BTreeMap<u32, Frame> = BTreeMap::new();
    let mut materials: BTreeMap<u32, Material> = BTreeMap::new();
    let mut pshells: BTreeMap<u32, Pshell> = BTreeMap::new();
    let mut pbars: BTreeMap<u32, Pbar> = BTreeMap::new();
    let mut pelas: BTreeMap<u32, f64> = BTreeMap::new();
    for c in cards {
        match c.name.as_str() {
            "CORD2R" => {
                if c.int(1, Some(0))? != 0 {
                    return Err(c.invalid(
                        "only CORD2R defined in the basic system (RID blank or 0) is supported",
                    ));
                }
                let p = |k: usize| -> Result<Vector3<f64>, FeError> {
                    Ok(Vector3::new(
                        c.real(k, None)?,
                        c.real(k + 1, None)?,
                        c.real(k + 2, None)?,
                    ))
                };
                let (a, b, cc) = (p(2)?, p(5)?, p(8)?);
                let z = (b - a)
                    .try_normalize(1e-12)
                    .ok_or_else(|| c.invalid("points A and B coincide"))?;
                let y = z
                    .cross(&(cc - a))
                    .try_normalize(1e-12)
                    .ok_or_else(|| c.invalid("point C lies on the z axis"))?;
                let x = y.cross(&z);
                frames.insert(
                    id(c, 0)?,
                    Frame {
                        origin: a,
                        axes: Matrix3::from_columns(&[x, y, z]),
                    },
                );
            }
            "MAT1" => {
                let e = c.real(1, Some(0.0))?;
                let g = c.real(2, Some(0.0))?;
                let nu = c.real(3, Some(0.0))?;
                let nu = match (e > 0.0, !c.blank(3), g > 0.0) {
                    (true, true, _) => nu,
                    (true, false, true) => e / (2.0 * g) - 1.0,
                    _ => return Err(c.invalid("needs E and one of G and NU")),
                };
                materials.insert(
                    id(c, 0)?,
                    Material {
                        youngs_modulus: e,
                        poisson_ratio: nu,
                        density: c.real(4, Some(0.0))?,
                    },
                );
            }
            "PSHELL" => {
                if !c.blank(3) && c.int(3, None)? != c.int(1, None)? {
                    return Err(
                        c.invalid("MID2 must be blank or equal to MID1 (one isotropic material)")
                    );
                }
                pshells.insert(
                    id(c, 0)?,
                    Pshell {
                        material: id(c, 1)?,
                        thickness: c.real(2, None)?,
                        bending_ratio: c.real(4, Some(1.0))?,
                        nsm: c.real(7, Some(0.0))?,
                    },
                );
            }
            "PBAR" => {
                pbars.insert(id(c, 0)?, bar_property(c, 5, 6)?);
            }
            "PBEAM" => {
                if !c.blank(5) && c.real(5, None)? != 0.0 {
                    return Err(c.invalid("I12 must be 0 (principal axes)"));
                }
                pbars.insert(id(c, 0)?, bar_property(c, 6, 7)?);
            }
            "PELAS" => {
                pelas.insert(id(c, 0)?, c.real(1, None)?);
            }
            _ => {}
        }
    }

    // Second pass: grids, in the order they come.
    let mut mesh = Mesh::default();
    let mut grid_index = BTreeMap::new();
    let mut permanent = Vec::new();
    for c in cards.iter().filter(|c| c.name == "GRID") {
        let gid = id(c, 0)?;
        let local = Vector3::new(
            c.real(2, Some(0.0))?,
            c.real(3, Some(0.0))?,
            c.real(4, Some(0.0))?,
        );
        let cp = c.int(1, Some(0))?;
        let position = if cp == 0 {
            local
        } else {
            let f = by_id(&frames, cp as u32, "coordinate system", c)?;
            f.origin + f.axes * local
        };
        if c.int(5, Some(0))? != 0 {
            return Err(
                c.invalid("a displacement system CD other than the basic one is not supported")
            );
        }
        let node = mesh.add_node(position);
        if grid_index.insert(gid, node).is_some() {
            return Err(c.invalid(&format!("GRID {gid} is defined twice")));
        }
        for d in components(c, 6)? {
            permanent.push((node, d));
        }
    }
    let node = |c: &Card, field: usize| -> Result<usize, FeError> {
        let g = id(c, field)?;
        grid_index.get(&g).copied().ok_or_else(|| {
            c.invalid(&format!(
                "refers to GRID {g}, which the deck does not define"
            ))
        })
    };
    mesh.constraints.extend(permanent);

    // Third pass: elements, masses, springs, constraints; anything else is an error.
    for c in cards {
        match c.name.as_str() {
            "GRID" | "CORD2R" | "MAT1" | "PSHELL" | "PBAR" | "PBEAM" | "PELAS" => {}
            name if IGNORED.contains(&name) => {}
            "CQUAD4" => {
                let p = by_id(&pshells, id(c, 1)?, "PSHELL", c)?;
                let m = *by_id(&materials, p.material, "MAT1", c)?;
                if !c.blank(7) && c.real(7, Some(0.0))? != 0.0 {
                    return Err(c.invalid("a ZOFFS offset is not supported"));
                }
                mesh.shells.push(Shell {
                    nodes: [node(c, 2)?, node(c, 3)?, node(c, 4)?, node(c, 5)?],
                    material: m,
                    thickness: p.thickness,
                    bending_thickness: p.thickness * p.bending_ratio.cbrt(),
                    extra_mass_per_area: p.nsm,
                });
            }
            "CBAR" | "CBEAM" => {
                let p = by_id(&pbars, id(c, 1)?, "PBAR/PBEAM", c)?;
                let m = *by_id(&materials, p.material, "MAT1", c)?;
                let (a, b) = (node(c, 2)?, node(c, 3)?);
                let orientation = if c.text(4).contains('.') {
                    Vector3::new(c.real(4, None)?, c.real(5, Some(0.0))?, c.real(6, Some(0.0))?)
                } else {
                    let g0 = node(c, 4)?;
                    mesh.nodes[g0] - mesh.nodes[a]
                };
                let pinned = (8..10).any(|k| c.int(k, Some(0)) != Ok(0));
                let offset = (10..16).any(|k| c.real(k, Some(0.0)) != Ok(0.0));
                if pinned || offset {
                    return Err(c.invalid("pin flags and offsets are not supported"));
                }
                mesh.beams.push(Beam {
                    nodes: [a, b],
                    material: m,
                    section: p.section,
                    orientation,
                    extra_mass_per_length: p.nsm,
                });
            }
            "CONM2" => {
                if c.int(2, Some(0))? != 0 {
                    return Err(c.invalid("CID other than the basic system is not supported"));
                }
                if (4..7).any(|k| c.real(k, Some(0.0)) != Ok(0.0)) {
                    return Err(c.invalid("an offset X1..X3 is not supported: put the mass on a grid at its centre"));
                }
                let i = |k: usize| c.real(k, Some(0.0));
                // Nastran lists the products of inertia with the sign convention of its inertia
                // matrix: I21, I31, I32 enter it negated.
                let (i11, i21, i22, i31, i32, i33) = (i(8)?, i(9)?, i(10)?, i(11)?, i(12)?, i(13)?);
                mesh.masses.push(PointMass {
                    node: node(c, 1)?,
                    mass: c.real(3, None)?,
                    inertia: Matrix3::new(i11, -i21, -i31, -i21, i22, -i32, -i31, -i32, i33),
                });
            }
            "CELAS1" | "CELAS2" | "CDAMP2" => {
                let value = if c.name == "CELAS1" { *by_id(&pelas, id(c, 1)?, "PELAS", c)? } else { c.real(1, None)? };
                let (c1, c2) = (components(c, 3)?, components(c, 5)?);
                let [d] = c1[..] else { return Err(c.invalid("C1 must be one component")) };
                let mut k = [0.0; 6];
                k[d] = value;
                let zero = [0.0; 6];
                let (stiffness, damping) = if c.name == "CDAMP2" { (zero, k) } else { (k, zero) };
                if c.blank(4) {
                    mesh.ground_springs.push(GroundSpring { node: node(c, 2)?, stiffness, damping });
                } else {
                    if c2 != c1 {
                        return Err(c.invalid("a spring between different components of its two grids is not supported"));
                    }
                    mesh.springs.push(Spring { nodes: [node(c, 2)?, node(c, 4)?], stiffness, damping });
                }
            }
            "SPC1" => {
                let dofs = components(c, 1)?;
                let mut grids = Vec::new();
                if c.text(3) == "THRU" {
                    for g in id(c, 2)?..=id(c, 4)? {
                        if let Some(n) = grid_index.get(&g) {
                            grids.push(*n);
                        }
                    }
                } else {
                    for k in 2..c.fields.len() {
                        if !c.blank(k) {
                            grids.push(node(c, k)?);
                        }
                    }
                }
                for n in grids {
                    mesh.constraints.extend(dofs.iter().map(|d| (n, *d)));
                }
            }
            "CTRIA3" => return Err(c.invalid("CTRIA3 is not supported (the shell element is a 4-node one); mesh with CQUAD4")),
            "RBE2" | "RBE3" => return Err(c.invalid("rigid elements are not supported yet; attach mounts and output points to grids of the structure")),
            other => {
                return Err(FeError::InvalidInput(format!(
                    "unsupported card {other} on line {}",
                    c.line
                )))
            }
        }
    }
    mesh.constraints.sort_unstable();
    mesh.constraints.dedup();
    Ok(NastranBody { mesh, grid_index })
}
