//! [`Mesh`] → Nastran bulk data in large-field format (16-column fields, so a real keeps 10 or
//! more significant digits; most values of a generated mesh are written exactly).
//!
//! GRID ids are node index + 1 (all in basic: a mesh with displacement frames is refused);
//! beam offsets and pin flags are written on the CBAR (OFFT GGG = basic here), shell offsets and
//! material angles on the CQUAD4/CTRIA3 (ZOFFS, THETA) of an isotropic sheet; elements are
//! numbered from 1 in the order CQUAD4, CTRIA3, CBAR, CONM2, CELAS2, CDAMP2, RBE2, RBE3,
//! CTETRA/CPENTA/CHEXA. Supports are SPC1 set 1 (a Nastran run needs `SPC = 1` in its
//! case control; [`super::parse_str`] applies the only set present). Named nodes are listed in
//! comments.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write;

use crate::fe::error::FeError;
use crate::fe::mesh::{Beam, Material, Mesh};
use crate::fe::shell::ShellSection;
use crate::fe::solid::SolidKind;

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

/// A bulk deck being written: one method per card kind, called in the order of the module
/// documentation, sharing the element counter and the material and property tables.
struct Deck<'m> {
    mesh: &'m Mesh,
    out: String,
    materials: Table,
    properties: Table,
    /// Id of the last element written.
    eid: u64,
}

impl<'m> Deck<'m> {
    fn new(mesh: &'m Mesh) -> Self {
        Self {
            mesh,
            out: String::new(),
            materials: Table::new(),
            properties: Table::new(),
            eid: 0,
        }
    }

    fn card(&mut self, name: &str, fields: &[Out]) -> Result<(), FeError> {
        card(&mut self.out, name, fields)
    }

    fn grid_id(&self, what: &str, node: usize) -> Result<Out, FeError> {
        check_node(self.mesh, what, node).map(Out::Int)
    }

    fn next_element(&mut self) -> Out {
        self.eid += 1;
        Out::Int(self.eid)
    }

    fn header(&mut self) {
        self.out
            .push_str("$ Nastran bulk data written by engine_mount_chassis (nastran), SI units\n");
        for (name, node) in &self.mesh.named_nodes {
            let _ = writeln!(self.out, "$ named node {name} = GRID {}", node + 1);
        }
        self.out.push_str("BEGIN BULK\n");
    }

    fn grids(&mut self) -> Result<(), FeError> {
        for (i, p) in self.mesh.nodes.iter().enumerate() {
            let fields = [
                Out::Int(i as u64 + 1),
                Out::Blank,
                Out::Real(p.x),
                Out::Real(p.y),
                Out::Real(p.z),
            ];
            card(&mut self.out, "GRID", &fields)?;
        }
        Ok(())
    }

    /// The MAT1 id of `m`, written on first use.
    fn mat1(&mut self, m: &Material) -> Result<u64, FeError> {
        let (id, new) = self
            .materials
            .id(&[m.youngs_modulus, m.poisson_ratio, m.density]);
        if new {
            self.card(
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
    fn pshell(&mut self, m: &Material, [t, bending_t, nsm]: [f64; 3]) -> Result<u64, FeError> {
        let mid = self.mat1(m)?;
        let ratio = (bending_t / t).powi(3);
        // The mesh's sheet shears over 5/6 of its bending thickness, Nastran over TS/T·T.
        let ts_t = 5.0 / 6.0 * bending_t / t;
        let (pid, new) = self.properties.id(&[0.0, mid as f64, t, ratio, nsm]);
        if new {
            self.card(
                "PSHELL",
                &[
                    Out::Int(pid),
                    Out::Int(mid),
                    Out::Real(t),
                    Out::Int(mid),
                    Out::Real(ratio),
                    Out::Int(mid),
                    Out::Real(ts_t),
                    Out::Real(nsm),
                ],
            )?;
        }
        Ok(pid)
    }

    /// A CQUAD4 or CTRIA3 of property `pid` on `nodes`, with THETA and ZOFFS when the sheet is
    /// offset.
    fn plate(
        &mut self,
        name: &str,
        what: &str,
        pid: u64,
        nodes: &[usize],
        placement: Option<[f64; 2]>,
    ) -> Result<(), FeError> {
        let mut fields = vec![self.next_element(), Out::Int(pid)];
        for &n in nodes {
            fields.push(self.grid_id(what, n)?);
        }
        if let Some([theta, zoffs]) = placement {
            fields.push(Out::Real(theta.to_degrees()));
            fields.push(Out::Real(zoffs));
        }
        self.card(name, &fields)
    }

    fn cquad4(&mut self) -> Result<(), FeError> {
        for (i, s) in self.mesh.shells.iter().enumerate() {
            let what = format!("shell {i}");
            let sheet = [s.thickness, s.bending_thickness, s.extra_mass_per_area];
            let placement = placement(&what, &s.material, sheet, s.section.as_deref())?;
            let pid = self.pshell(&s.material, sheet)?;
            self.plate("CQUAD4", &what, pid, &s.nodes, placement)?;
        }
        Ok(())
    }

    fn ctria3(&mut self) -> Result<(), FeError> {
        for (i, t) in self.mesh.triangles.iter().enumerate() {
            let what = format!("triangle {i}");
            let sheet = [t.thickness, t.bending_thickness, t.extra_mass_per_area];
            let placement = placement(&what, &t.material, sheet, t.section.as_deref())?;
            let pid = self.pshell(&t.material, sheet)?;
            self.plate("CTRIA3", &what, pid, &t.nodes, placement)?;
        }
        Ok(())
    }

    /// The PBAR id of a beam's section and non-structural mass, written on first use.
    fn pbar(&mut self, b: &Beam) -> Result<u64, FeError> {
        let mid = self.mat1(&b.material)?;
        let s = &b.section;
        let nsm = b.extra_mass_per_length;
        // PBAR K1/K2 = 0.0 reads back as rigid in shear, the same as blank.
        let k = [s.shear_factor_y, s.shear_factor_z].map(|k| k.unwrap_or(0.0));
        let values = [1.0, mid as f64, s.area, s.iz, s.iy, s.j, nsm, k[0], k[1]];
        let (pid, new) = self.properties.id(&values);
        if new {
            let mut fields = vec![
                Out::Int(pid),
                Out::Int(mid),
                Out::Real(s.area),
                Out::Real(s.iz),
                Out::Real(s.iy),
                Out::Real(s.j),
                Out::Real(nsm),
            ];
            if k.iter().any(|&k| k != 0.0) {
                // Field 9 and the stress recovery points C1 … F2 stay blank.
                fields.extend((0..9).map(|_| Out::Blank));
                fields.extend([Out::Real(k[0]), Out::Real(k[1])]);
            }
            self.card("PBAR", &fields)?;
        }
        Ok(pid)
    }

    fn cbar(&mut self) -> Result<(), FeError> {
        for (i, b) in self.mesh.beams.iter().enumerate() {
            let pid = self.pbar(b)?;
            let what = format!("beam {i}");
            let mut fields = vec![
                self.next_element(),
                Out::Int(pid),
                self.grid_id(&what, b.nodes[0])?,
                self.grid_id(&what, b.nodes[1])?,
                Out::Real(b.orientation.x),
                Out::Real(b.orientation.y),
                Out::Real(b.orientation.z),
            ];
            if let Some(ends) = self.mesh.beam_ends.get(&i) {
                // OFFT blank (GGG): the grids are written in basic, so their displacement
                // systems are basic too.
                fields.push(Out::Blank);
                for pins in ends.pins {
                    let digits = (0..6)
                        .filter(|&d| pins[d])
                        .fold(0u64, |acc, d| acc * 10 + d as u64 + 1);
                    fields.push(if digits == 0 {
                        Out::Blank
                    } else {
                        Out::Int(digits)
                    });
                }
                for w in ends.offsets {
                    fields.extend(w.iter().map(|&c| Out::Real(c)));
                }
            }
            self.card("CBAR", &fields)?;
        }
        Ok(())
    }

    fn conm2(&mut self) -> Result<(), FeError> {
        for (i, m) in self.mesh.masses.iter().enumerate() {
            let j = &m.inertia;
            // Products of inertia are entered positive (I21 = ∫x1 x2 dm = −J21): see to_mesh.
            let fields = [
                self.next_element(),
                self.grid_id(&format!("point mass {i}"), m.node)?,
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
            ];
            self.card("CONM2", &fields)?;
        }
        Ok(())
    }

    /// CELAS2 and CDAMP2 of the non-zero components of a spring-damper between `grids` (one
    /// grid: to ground).
    fn scalar(
        &mut self,
        grids: &[u64],
        stiffness: &[f64; 6],
        damping: &[f64; 6],
    ) -> Result<(), FeError> {
        for d in 0..6 {
            for (name, value) in [("CELAS2", stiffness[d]), ("CDAMP2", damping[d])] {
                if value != 0.0 {
                    let mut fields = vec![self.next_element(), Out::Real(value)];
                    for &g in grids {
                        fields.push(Out::Int(g));
                        fields.push(Out::Int(d as u64 + 1));
                    }
                    self.card(name, &fields)?;
                }
            }
        }
        Ok(())
    }

    fn celas2_cdamp2(&mut self) -> Result<(), FeError> {
        let mesh = self.mesh;
        for (i, s) in mesh.ground_springs.iter().enumerate() {
            let g = check_node(mesh, &format!("ground spring {i}"), s.node)?;
            self.scalar(&[g], &s.stiffness, &s.damping)?;
        }
        for (i, s) in mesh.springs.iter().enumerate() {
            let what = format!("spring {i}");
            let ends = [
                check_node(mesh, &what, s.nodes[0])?,
                check_node(mesh, &what, s.nodes[1])?,
            ];
            self.scalar(&ends, &s.stiffness, &s.damping)?;
        }
        Ok(())
    }

    fn rbe2(&mut self) -> Result<(), FeError> {
        for (i, l) in self.mesh.rigid_links.iter().enumerate() {
            let what = format!("rigid link {i}");
            let mut fields = vec![
                self.next_element(),
                self.grid_id(&what, l.independent)?,
                digits(&l.components)?,
            ];
            for &d in &l.dependent {
                fields.push(self.grid_id(&what, d)?);
            }
            self.card("RBE2", &fields)?;
        }
        Ok(())
    }

    fn rbe3(&mut self) -> Result<(), FeError> {
        for (i, l) in self.mesh.interpolation_links.iter().enumerate() {
            let what = format!("interpolation link {i}");
            let mut fields = vec![
                self.next_element(),
                Out::Blank,
                self.grid_id(&what, l.reference)?,
                digits(&l.reference_components)?,
            ];
            for group in &l.sources {
                fields.push(Out::Real(group.weight));
                fields.push(digits(&group.components)?);
                for &n in &group.nodes {
                    fields.push(self.grid_id(&what, n)?);
                }
            }
            self.card("RBE3", &fields)?;
        }
        Ok(())
    }

    /// CTETRA / CPENTA / CHEXA with a PSOLID per material (defaults: IN, ISOP, FCTN blank).
    fn solids(&mut self) -> Result<(), FeError> {
        for (i, s) in self.mesh.solids.iter().enumerate() {
            let what = format!("solid {i}");
            let kind = SolidKind::from_node_count(s.nodes.len()).ok_or_else(|| {
                FeError::Mesh(format!("{what}: {} nodes (4, 6, 8 or 10)", s.nodes.len()))
            })?;
            let mid = self.mat1(&s.material)?;
            let (pid, new) = self.properties.id(&[2.0, mid as f64]);
            if new {
                self.card("PSOLID", &[Out::Int(pid), Out::Int(mid)])?;
            }
            let mut fields = vec![self.next_element(), Out::Int(pid)];
            for &n in &s.nodes {
                fields.push(self.grid_id(&what, n)?);
            }
            self.card(kind.card(), &fields)?;
        }
        Ok(())
    }

    /// The constraints as SPC1 set 1, one card per component mask.
    fn spc1(&mut self) -> Result<(), FeError> {
        let mut fixed: BTreeMap<usize, [bool; 6]> = BTreeMap::new();
        for &(node, d) in &self.mesh.constraints {
            check_node(self.mesh, "constraint", node)?;
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
            self.card("SPC1", &fields)?;
        }
        Ok(())
    }
}

/// Writes `mesh` as bulk data (BEGIN BULK … ENDDATA).
pub fn write_bulk_deck(mesh: &Mesh) -> Result<String, FeError> {
    if !mesh.bushes.is_empty() {
        return Err(FeError::Mesh(format!(
            "the mesh has {} bushes (CBUSH); writing them is not supported",
            mesh.bushes.len()
        )));
    }
    if let Some(node) = mesh.displacement_frames.keys().next() {
        return Err(FeError::Mesh(format!(
            "node {node} has a displacement frame (GRID CD); writing displacement frames is not \
             supported"
        )));
    }
    let mut deck = Deck::new(mesh);
    deck.header();
    deck.grids()?;
    deck.cquad4()?;
    deck.ctria3()?;
    deck.cbar()?;
    deck.conm2()?;
    deck.celas2_cdamp2()?;
    deck.rbe2()?;
    deck.rbe3()?;
    deck.solids()?;
    deck.spc1()?;
    deck.out.push_str("ENDDATA\n");
    Ok(deck.out)
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
    use crate::nastran::parse_real;

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
