//! Shells: PSHELL with its MID1/MID2/MID3 materials (MAT1, MAT2, MAT8), THETA/MCID and
//! ZOFFS of CQUAD4/CTRIA3 → [`Shell`] / [`TriShell`] (with a [`ShellSection`] unless the
//! element is the plain isotropic sheet the mesh has always had).

use nalgebra::{Matrix2, Matrix3, Vector3};

use super::super::cards::{Pshell, ShellMaterialCard};
use super::super::lexer::Loc;
use super::{mesh_error, moduli, node_of, Cards, NastranBody, Systems};
use crate::fe::elements::Entity;
use crate::fe::error::FeError;
use crate::fe::mesh::{Material, Shell, TriShell};
use crate::fe::shell::ShellSection;

/// A shell material as the section needs it.
struct Resolved {
    /// Plane-stress matrix (Pa) in material axes.
    plane: Matrix3<f64>,
    /// Transverse shear moduli (Pa) in material axes; `None`: rigid (MAT8 G1Z, G2Z blank).
    shear: Option<Matrix2<f64>>,
    rho: f64,
    /// (E, ν) when the material is a MAT1.
    isotropic: Option<(f64, f64)>,
}

/// Material `mid` as PSHELL field `field` uses it.
///
/// Long on purpose: one match over the material cards a PSHELL field may name (MAT1, MAT2, MAT8)
/// and the field's role (membrane, bending, shear), each refusal naming the card and field.
fn resolve(c: &Cards, p: &Pshell, field: &str, mid: u32, user: &str) -> Result<Resolved, FeError> {
    let who = format!("PSHELL {} (used by {user}) {field}", p.id);
    match (c.materials.get(&mid), c.shell_materials.get(&mid)) {
        (Some(_), Some(other)) => Err(mesh_error(
            &p.line,
            format!(
                "{who}: material {mid} is defined both by a MAT1 and by a {} (material ids \
                 are shared by MAT1, MAT2 and MAT8)",
                match other {
                    ShellMaterialCard::Mat2 { .. } => "MAT2",
                    ShellMaterialCard::Mat8 { .. } => "MAT8",
                }
            ),
        )),
        (None, None) => Err(mesh_error(
            &p.line,
            format!("{who}: material {mid} not found: no MAT1 {mid}, MAT2 {mid} or MAT8 {mid}"),
        )),
        (Some(m), None) => {
            let (e, g, nu) = moduli(m, user)?;
            if (g / (e / (2.0 * (1.0 + nu))) - 1.0).abs() > 0.01 {
                return Err(mesh_error(
                    &m.line,
                    format!(
                        "MAT1 {} (used by {user}): G = {g} differs from E / 2(1 + NU) = {} by \
                         more than 1 %; the isotropic shell needs consistent E, G, NU",
                        m.id,
                        e / (2.0 * (1.0 + nu))
                    ),
                ));
            }
            let f = e / (1.0 - nu * nu);
            Ok(Resolved {
                plane: Matrix3::new(f, nu * f, 0.0, nu * f, f, 0.0, 0.0, 0.0, g),
                shear: Some(Matrix2::identity() * g),
                rho: m.rho,
                isotropic: Some((e, nu)),
            })
        }
        (None, Some(ShellMaterialCard::Mat2 { id, g, rho, line })) => {
            // Nastran: a MAT2 used for transverse shear gives [G11 G12; G12 G22], and G13, G23,
            // G33 must then be blank.
            let shear = Matrix2::new(g[(0, 0)], g[(0, 1)], g[(0, 1)], g[(1, 1)]);
            if field == "MID3" && (g[(0, 2)] != 0.0 || g[(1, 2)] != 0.0 || g[(2, 2)] != 0.0) {
                return Err(mesh_error(
                    line,
                    format!(
                        "MAT2 {id} (MID3 of PSHELL {}, used by {user}): a transverse shear \
                         MAT2 takes G11, G12, G22; G13, G23, G33 must be blank",
                        p.id
                    ),
                ));
            }
            Ok(Resolved {
                plane: *g,
                shear: Some(shear),
                rho: *rho,
                isotropic: None,
            })
        }
        (
            None,
            Some(ShellMaterialCard::Mat8 {
                id,
                e1,
                e2,
                nu12,
                g12,
                g1z,
                g2z,
                rho,
                line,
            }),
        ) => {
            let nu21 = nu12 * e2 / e1;
            let den = 1.0 - nu12 * nu21;
            if den.is_nan() || den <= 0.0 {
                return Err(mesh_error(
                    line,
                    format!(
                        "MAT8 {id} (used by {user}): 1 − NU12² E2/E1 = {den} must be > 0 \
                         (the lamina would not be stable)"
                    ),
                ));
            }
            let shear = match (g1z, g2z) {
                (Some(a), Some(b)) => Some(Matrix2::new(*a, 0.0, 0.0, *b)),
                (None, None) => None,
                _ => {
                    return Err(mesh_error(
                        line,
                        format!(
                            "MAT8 {id} (used by {user}): give both G1Z and G2Z or neither \
                             (blank means rigid in transverse shear)"
                        ),
                    ))
                }
            };
            Ok(Resolved {
                plane: Matrix3::new(
                    e1 / den,
                    nu12 * e2 / den,
                    0.0,
                    nu12 * e2 / den,
                    e2 / den,
                    0.0,
                    0.0,
                    0.0,
                    *g12,
                ),
                shear,
                rho: *rho,
                isotropic: None,
            })
        }
    }
}

/// THETA (rad) equivalent to MCID: the angle about the element normal from the side G1 → G2
/// to the x axis of system `mcid` (0: basic) projected onto the element plane.
fn mcid_angle(
    systems: &Systems,
    mcid: i64,
    corners: &[Vector3<f64>],
    line: &Loc,
    user: &str,
) -> Result<f64, FeError> {
    let x = if mcid == 0 {
        Vector3::x()
    } else {
        let id = u32::try_from(mcid)
            .map_err(|_| mesh_error(line, format!("{user}: MCID {mcid} is out of range")))?;
        systems
            .rectangular(id, line, &format!("{user} MCID"))?
            .1
            .column(0)
            .into_owned()
    };
    // The shells' own normals: diagonals for the quadrilateral, the first two sides for the
    // triangle.
    let normal = match corners {
        [a, b, c, d] => (c - a).cross(&(d - b)),
        [a, b, c] => (b - a).cross(&(c - a)),
        _ => Vector3::zeros(),
    };
    let n = normal.normalize();
    let project = |v: Vector3<f64>| v - n * n.dot(&v);
    let (side, axis) = (project(corners[1] - corners[0]), project(x));
    if !(axis.norm() > 1e-6 * x.norm() && n.iter().all(|v| v.is_finite())) {
        return Err(mesh_error(
            line,
            format!(
                "{user}: the x axis of MCID {mcid} is normal to the element: it defines no \
                 material direction in its plane"
            ),
        ));
    }
    Ok(side.cross(&axis).dot(&n).atan2(side.dot(&axis)))
}

/// Long on purpose: one pass over the PSHELL rules, then one arm per element kind.
pub(super) fn add_shells(
    c: &Cards,
    systems: &Systems,
    body: &mut NastranBody,
) -> Result<(), FeError> {
    for (&id, (plate, name)) in &c.plates {
        let user = format!("{name} {id}");
        let line = &plate.line;
        let p = c.shell_properties.get(&plate.pid).ok_or_else(|| {
            mesh_error(
                line,
                format!("{user}: property PSHELL {} not found", plate.pid),
            )
        })?;
        let fail =
            |why: String| mesh_error(&p.line, format!("PSHELL {} (used by {user}): {why}", p.id));
        let mid1 = p.mid1.ok_or_else(|| {
            fail("MID1 is blank: shells without membrane stiffness are not supported".into())
        })?;
        let mid2 = match p.mid2 {
            Some(m) if m > 0 && m <= u32::MAX as i64 => m as u32,
            other => {
                return Err(fail(format!(
                    "MID2 = {other:?}: membrane-only (blank) and plane-strain (−1) shells are \
                     not supported; give the bending material"
                )))
            }
        };
        if !(p.t > 0.0 && p.bending_ratio > 0.0 && p.ts_t > 0.0) {
            return Err(fail(format!(
                "T = {}, 12I/T**3 = {} and TS/T = {} must be > 0",
                p.t, p.bending_ratio, p.ts_t
            )));
        }
        let m1 = resolve(c, p, "MID1", mid1, &user)?;
        let m2 = resolve(c, p, "MID2", mid2, &user)?;
        let m3 = p
            .mid3
            .map(|m| resolve(c, p, "MID3", m, &user))
            .transpose()?;
        let isotropic = m1.isotropic.is_some()
            && m2.isotropic.is_some()
            && m3.as_ref().is_none_or(|m| m.isotropic.is_some());
        let nodes = plate
            .grids
            .iter()
            .map(|&g| node_of(body, g, line, &user))
            .collect::<Result<Vec<_>, _>>()?;
        // An isotropic sheet has no material direction: its MCID is not even looked up.
        let material_angle = match plate.mcid {
            Some(mcid) if !isotropic => {
                let corners: Vec<_> = nodes.iter().map(|&k| body.mesh.nodes[k]).collect();
                mcid_angle(systems, mcid, &corners, line, &user)?
            }
            _ => plate.theta.to_radians(),
        };
        if !(plate.theta.is_finite() && plate.zoffs.is_finite()) {
            return Err(mesh_error(
                line,
                format!("{user}: THETA and ZOFFS must be finite"),
            ));
        }
        let bending_thickness = p.t * p.bending_ratio.cbrt();
        // The sheet the mesh has always had: one MAT1 for membrane, bending and shear, shear
        // thickness 5/6 of the bending thickness (TS/T = 5/6 for 12I/T³ = 1, as the deck writer
        // writes it otherwise), no offset; anything else carries a section.
        let plain_ts_t = 5.0 / 6.0 * p.bending_ratio.cbrt();
        let plain = m1.isotropic.is_some()
            && m2.isotropic == m1.isotropic
            && m3.as_ref().is_some_and(|m| m.isotropic == m1.isotropic)
            && (p.ts_t / plain_ts_t - 1.0).abs() < 1e-5
            && plate.zoffs == 0.0;
        let section = (!plain).then(|| {
            Box::new(ShellSection {
                membrane: m1.plane * p.t,
                bending: m2.plane * (p.bending_ratio * p.t.powi(3) / 12.0),
                transverse_shear: m3
                    .as_ref()
                    .and_then(|m| m.shear)
                    .map(|s| s * (p.ts_t * p.t)),
                material_angle,
                offset: plate.zoffs,
            })
        });
        if let Some(s) = &section {
            s.validate(&format!(
                "Nastran bulk data line {line}: {user} with PSHELL {}",
                p.id
            ))?;
        }
        // E and ν only matter without a section; with one they describe MID1 for reference.
        let (e, nu) = m1.isotropic.unwrap_or((m1.plane[(0, 0)], 0.0));
        let material = Material {
            youngs_modulus: e,
            poisson_ratio: nu,
            density: m1.rho * c.mass_scale,
        };
        let extra_mass_per_area = p.nsm * c.mass_scale;
        if let [a, b, cc, d] = nodes[..] {
            body.mesh.shells.push(Shell {
                nodes: [a, b, cc, d],
                material,
                thickness: p.t,
                bending_thickness,
                extra_mass_per_area,
                section,
            });
            body.element_ids.push(Entity::Shell, id);
        } else if let [a, b, cc] = nodes[..] {
            body.mesh.triangles.push(TriShell {
                nodes: [a, b, cc],
                material,
                thickness: p.t,
                bending_thickness,
                extra_mass_per_area,
                section,
            });
            body.element_ids.push(Entity::Triangle, id);
        }
    }
    Ok(())
}
