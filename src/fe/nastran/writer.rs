//! [`Mesh`] → Nastran bulk data in large-field format (16-column fields, so a real keeps 10 or
//! more significant digits; most values of a generated mesh are written exactly).
//!
//! GRID ids are node index + 1; elements are numbered from 1 in the order CQUAD4, CTRIA3, CBAR, CONM2,
//! CELAS2, CDAMP2, RBE2, RBE3. Supports are SPC1 set 1 (a Nastran run needs `SPC = 1` in its
//! case control; [`super::parse_str`] applies the only set present). Named nodes are listed in
//! comments.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write;

use crate::fe::error::FeError;
use crate::fe::mesh::{Material, Mesh};

/// A field of a card being written.
enum Out {
    Blank,
    Int(u64),
    Real(f64),
}

/// Shortest Nastran spelling of `x` in at most 16 characters: exact when the shortest
/// round-trip decimal fits, else rounded to the most significant digits that fit.
fn real16(x: f64) -> Result<String, FeError> {
    if !x.is_finite() {
        return Err(FeError::InvalidInput(format!(
            "cannot write the non-finite value {x} to bulk data"
        )));
    }
    if x == 0.0 {
        return Ok("0.".to_string());
    }
    // Exponent form with Nastran's implied exponent: 2.1e11 → "2.1+11".
    let nastran = |s: String| -> String {
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mut m = mantissa.to_string();
        if !m.contains('.') {
            m.push('.');
        }
        match exponent {
            "0" => m,
            e if e.starts_with('-') => format!("{m}{e}"),
            e => format!("{m}+{e}"),
        }
    };
    let mut plain = format!("{x}");
    if !plain.contains('.') {
        plain.push('.');
    }
    let exact = nastran(format!("{x:e}"));
    let best = if plain.len() <= exact.len() {
        plain
    } else {
        exact
    };
    if best.len() <= 16 {
        return Ok(best);
    }
    for digits in (1..16).rev() {
        let s = nastran(format!("{x:.digits$e}"));
        if s.len() <= 16 {
            return Ok(s);
        }
    }
    Err(FeError::InvalidInput(format!(
        "cannot write {x} in 16 columns"
    )))
}

fn card(out: &mut String, name: &str, fields: &[Out]) -> Result<(), FeError> {
    let _ = write!(out, "{:<8}", format!("{name}*"));
    let mut rendered = Vec::with_capacity(fields.len());
    for f in fields {
        rendered.push(match f {
            Out::Blank => String::new(),
            Out::Int(v) => v.to_string(),
            Out::Real(v) => real16(*v)?,
        });
    }
    for (k, text) in rendered.iter().enumerate() {
        if k > 0 && k % 4 == 0 {
            out.push_str("\n*       ");
        }
        let _ = write!(out, "{text:>16}");
    }
    out.push('\n');
    Ok(())
}

fn digits(mask: &[bool; 6]) -> Result<Out, FeError> {
    let s: String = (0..6)
        .filter(|&d| mask[d])
        .map(|d| char::from(b'1' + d as u8))
        .collect();
    if s.is_empty() {
        return Err(FeError::InvalidInput(
            "a link or support lists no components".into(),
        ));
    }
    Ok(Out::Int(s.parse().unwrap_or(0)))
}

fn check_node(mesh: &Mesh, what: &str, node: usize) -> Result<u64, FeError> {
    if node < mesh.nodes.len() {
        Ok(node as u64 + 1)
    } else {
        Err(FeError::Mesh(format!(
            "{what} refers to node {node}, mesh has {} nodes",
            mesh.nodes.len()
        )))
    }
}

/// Deduplicates properties and materials by the bit patterns of their values.
struct Table {
    ids: HashMap<Vec<u64>, u64>,
}

impl Table {
    fn new() -> Self {
        Self {
            ids: HashMap::new(),
        }
    }

    /// The id of `values`, and whether it is new.
    fn id(&mut self, values: &[f64]) -> (u64, bool) {
        let key: Vec<u64> = values.iter().map(|v| v.to_bits()).collect();
        let next = self.ids.len() as u64 + 1;
        match self.ids.get(&key) {
            Some(id) => (*id, false),
            None => {
                self.ids.insert(key, next);
                (next, true)
            }
        }
    }
}

fn material(out: &mut String, table: &mut Table, m: &Material) -> Result<u64, FeError> {
    let (id, new) = table.id(&[m.youngs_modulus, m.poisson_ratio, m.density]);
    if new {
        card(
            out,
            "MAT1",
            &[
                Out::Int(id),
                Out::Real(m.youngs_modulus),
                Out::Blank,
                Out::Real(m.poisson_ratio),
                Out::Real(m.density),
            ],
        )?;
    }
    Ok(id)
}

/// The PSHELL id of a shell section, written on first use (MID1 = MID2 = MID3, so Nastran also
/// includes transverse shear, like the four-node shell).
fn shell_property(
    out: &mut String,
    materials: &mut Table,
    properties: &mut Table,
    m: &Material,
    thickness: f64,
    bending_thickness: f64,
    extra_mass_per_area: f64,
) -> Result<u64, FeError> {
    let mid = material(out, materials, m)?;
    let ratio = (bending_thickness / thickness).powi(3);
    let (pid, new) = properties.id(&[0.0, mid as f64, thickness, ratio, extra_mass_per_area]);
    if new {
        card(
            out,
            "PSHELL",
            &[
                Out::Int(pid),
                Out::Int(mid),
                Out::Real(thickness),
                Out::Int(mid),
                Out::Real(ratio),
                Out::Int(mid),
                Out::Blank,
                Out::Real(extra_mass_per_area),
            ],
        )?;
    }
    Ok(pid)
}

/// Writes `mesh` as bulk data (BEGIN BULK … ENDDATA).
pub fn write_bulk_deck(mesh: &Mesh) -> Result<String, FeError> {
    let mut out = String::new();
    out.push_str("$ Nastran bulk data written by engine_mount_chassis (fe::nastran), SI units\n");
    for (name, node) in &mesh.named_nodes {
        let _ = writeln!(out, "$ named node {name} = GRID {}", node + 1);
    }
    out.push_str("BEGIN BULK\n");
    for (i, p) in mesh.nodes.iter().enumerate() {
        card(
            &mut out,
            "GRID",
            &[
                Out::Int(i as u64 + 1),
                Out::Blank,
                Out::Real(p.x),
                Out::Real(p.y),
                Out::Real(p.z),
            ],
        )?;
    }
    let mut materials = Table::new();
    let mut properties = Table::new();
    let mut eid = 0u64;
    for (i, s) in mesh.shells.iter().enumerate() {
        let pid = shell_property(
            &mut out,
            &mut materials,
            &mut properties,
            &s.material,
            s.thickness,
            s.bending_thickness,
            s.extra_mass_per_area,
        )?;
        eid += 1;
        let mut fields = vec![Out::Int(eid), Out::Int(pid)];
        for &n in &s.nodes {
            fields.push(Out::Int(check_node(mesh, &format!("shell {i}"), n)?));
        }
        card(&mut out, "CQUAD4", &fields)?;
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        let pid = shell_property(
            &mut out,
            &mut materials,
            &mut properties,
            &t.material,
            t.thickness,
            t.bending_thickness,
            t.extra_mass_per_area,
        )?;
        eid += 1;
        let mut fields = vec![Out::Int(eid), Out::Int(pid)];
        for &n in &t.nodes {
            fields.push(Out::Int(check_node(mesh, &format!("triangle {i}"), n)?));
        }
        card(&mut out, "CTRIA3", &fields)?;
    }
    for (i, b) in mesh.beams.iter().enumerate() {
        let mid = material(&mut out, &mut materials, &b.material)?;
        let s = &b.section;
        let (pid, new) = properties.id(&[
            1.0,
            mid as f64,
            s.area,
            s.iz,
            s.iy,
            s.j,
            b.extra_mass_per_length,
        ]);
        if new {
            card(
                &mut out,
                "PBAR",
                &[
                    Out::Int(pid),
                    Out::Int(mid),
                    Out::Real(s.area),
                    Out::Real(s.iz),
                    Out::Real(s.iy),
                    Out::Real(s.j),
                    Out::Real(b.extra_mass_per_length),
                ],
            )?;
        }
        eid += 1;
        let what = format!("beam {i}");
        card(
            &mut out,
            "CBAR",
            &[
                Out::Int(eid),
                Out::Int(pid),
                Out::Int(check_node(mesh, &what, b.nodes[0])?),
                Out::Int(check_node(mesh, &what, b.nodes[1])?),
                Out::Real(b.orientation.x),
                Out::Real(b.orientation.y),
                Out::Real(b.orientation.z),
            ],
        )?;
    }
    for (i, m) in mesh.masses.iter().enumerate() {
        let j = &m.inertia;
        eid += 1;
        // Products of inertia are entered positive (I21 = ∫x1 x2 dm = −J21): see to_mesh.
        card(
            &mut out,
            "CONM2",
            &[
                Out::Int(eid),
                Out::Int(check_node(mesh, &format!("point mass {i}"), m.node)?),
                Out::Blank,
                Out::Real(m.mass),
                Out::Blank,
                Out::Blank,
                Out::Blank,
                Out::Blank,
                Out::Real(j[(0, 0)]),
                Out::Real(-j[(1, 0)]),
                Out::Real(j[(1, 1)]),
                Out::Real(-j[(2, 0)]),
                Out::Real(-j[(2, 1)]),
                Out::Real(j[(2, 2)]),
            ],
        )?;
    }
    let mut scalar = |out: &mut String, name: &str, value: f64, ends: &[(u64, usize)]| {
        eid += 1;
        let mut fields = vec![Out::Int(eid), Out::Real(value)];
        for &(g, c) in ends {
            fields.push(Out::Int(g));
            fields.push(Out::Int(c as u64 + 1));
        }
        card(out, name, &fields)
    };
    for (i, s) in mesh.ground_springs.iter().enumerate() {
        let g = check_node(mesh, &format!("ground spring {i}"), s.node)?;
        for d in 0..6 {
            if s.stiffness[d] != 0.0 {
                scalar(&mut out, "CELAS2", s.stiffness[d], &[(g, d)])?;
            }
            if s.damping[d] != 0.0 {
                scalar(&mut out, "CDAMP2", s.damping[d], &[(g, d)])?;
            }
        }
    }
    for (i, s) in mesh.springs.iter().enumerate() {
        let what = format!("spring {i}");
        let (a, b) = (
            check_node(mesh, &what, s.nodes[0])?,
            check_node(mesh, &what, s.nodes[1])?,
        );
        for d in 0..6 {
            if s.stiffness[d] != 0.0 {
                scalar(&mut out, "CELAS2", s.stiffness[d], &[(a, d), (b, d)])?;
            }
            if s.damping[d] != 0.0 {
                scalar(&mut out, "CDAMP2", s.damping[d], &[(a, d), (b, d)])?;
            }
        }
    }
    for (i, l) in mesh.rigid_links.iter().enumerate() {
        let what = format!("rigid link {i}");
        eid += 1;
        let mut fields = vec![
            Out::Int(eid),
            Out::Int(check_node(mesh, &what, l.independent)?),
            digits(&l.components)?,
        ];
        for &d in &l.dependent {
            fields.push(Out::Int(check_node(mesh, &what, d)?));
        }
        card(&mut out, "RBE2", &fields)?;
    }
    for (i, l) in mesh.interpolation_links.iter().enumerate() {
        let what = format!("interpolation link {i}");
        eid += 1;
        let mut fields = vec![
            Out::Int(eid),
            Out::Blank,
            Out::Int(check_node(mesh, &what, l.reference)?),
            digits(&l.reference_components)?,
        ];
        for group in &l.sources {
            fields.push(Out::Real(group.weight));
            fields.push(digits(&group.components)?);
            for &n in &group.nodes {
                fields.push(Out::Int(check_node(mesh, &what, n)?));
            }
        }
        card(&mut out, "RBE3", &fields)?;
    }
    let mut fixed: BTreeMap<usize, [bool; 6]> = BTreeMap::new();
    for &(node, d) in &mesh.constraints {
        check_node(mesh, "constraint", node)?;
        if d >= 6 {
            return Err(FeError::Mesh(format!(
                "constraint on node {node}: dof {d} > 5"
            )));
        }
        fixed.entry(node).or_insert([false; 6])[d] = true;
    }
    let mut by_mask: BTreeMap<[bool; 6], Vec<u64>> = BTreeMap::new();
    for (node, mask) in fixed {
        by_mask.entry(mask).or_default().push(node as u64 + 1);
    }
    for (mask, grids) in by_mask {
        let mut fields = vec![Out::Int(1), digits(&mask)?];
        fields.extend(grids.into_iter().map(Out::Int));
        card(&mut out, "SPC1", &fields)?;
    }
    out.push_str("ENDDATA\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::nastran::parse_real;

    #[test]
    fn reals_fit_16_columns_and_read_back() {
        for x in [
            0.1 + 0.2,
            -2.54,
            210e9,
            7850.0,
            1.0 / 3.0,
            -1.2345678901234567e-300,
            6.02214076e23,
            5e-324,
            1e300,
        ] {
            let s = real16(x).unwrap();
            assert!(s.len() <= 16, "{s}");
            let back = parse_real(&s).unwrap();
            // Ten significant digits even with a three-digit exponent.
            assert!((back - x).abs() <= 5e-10 * x.abs(), "{x} → {s} → {back}");
        }
        assert_eq!(real16(-2.54).unwrap(), "-2.54");
        assert_eq!(real16(210e9).unwrap(), "2.1+11");
        assert_eq!(real16(0.25).unwrap(), "0.25");
        assert!(real16(f64::NAN).is_err());
    }
}
