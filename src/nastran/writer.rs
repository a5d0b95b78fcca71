//! [`Mesh`] → Nastran bulk data in large-field format (16-column fields, so a real keeps 10 or
//! more significant digits; most values of a generated mesh are written exactly).
//!
//! GRID ids are node index + 1 (all in basic: a mesh with displacement frames is refused);
//! each entity writes its own cards ([`crate::fe::element::Element::write_bulk`]): beam offsets
//! and pin flags on the CBAR (OFFT GGG = basic here), shell offsets and material angles on the
//! CQUAD4/CTRIA3 (ZOFFS, THETA) of an isotropic sheet; materials and properties are written once,
//! on first use; elements are numbered from 1 in the registry's order
//! ([`crate::fe::elements::Entity::ALL`]: CBAR, CQUAD4, CTRIA3, CONM2, CELAS2/CDAMP2 to ground,
//! then between grids, CTETRA/CPENTA/CHEXA, RBE2, RBE3; bushes are refused). Supports are SPC1 set 1 (a Nastran run needs `SPC = 1` in its
//! case control; [`super::parse_str`] applies the only set present). Named nodes are listed in
//! comments.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write;

use crate::fe::element::{BulkWriter, Field};
use crate::fe::elements::Entity;
use crate::fe::error::FeError;
use crate::fe::mesh::{Material, Mesh};

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

fn card(out: &mut String, name: &str, fields: &[Field]) -> Result<(), FeError> {
    let _ = write!(out, "{:<8}", format!("{name}*"));
    let mut rendered = Vec::with_capacity(fields.len());
    for f in fields {
        rendered.push(match f {
            Field::Blank => String::new(),
            Field::Int(v) => v.to_string(),
            Field::Real(v) => real16(*v)?,
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

/// Deduplicates properties and materials by their card and the bit patterns of their values.
struct Table {
    ids: HashMap<(String, Vec<u64>), u64>,
}

impl Table {
    fn new() -> Self {
        Self {
            ids: HashMap::new(),
        }
    }

    /// The id of `values` of `card`, and whether it is new.
    fn id(&mut self, card: &str, values: &[f64]) -> (u64, bool) {
        let key = (
            card.to_string(),
            values.iter().map(|v| v.to_bits()).collect(),
        );
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

/// A bulk deck being written: the element counter and the material and property tables the
/// elements share ([`BulkWriter`]).
struct Deck<'m> {
    mesh: &'m Mesh,
    out: String,
    materials: Table,
    properties: Table,
    /// Id of the last element written.
    eid: u64,
}

impl BulkWriter for Deck<'_> {
    fn element_id(&mut self) -> Field {
        self.eid += 1;
        Field::Int(self.eid)
    }

    fn grid(&self, what: &str, node: usize) -> Result<Field, FeError> {
        check_node(self.mesh, what, node).map(Field::Int)
    }

    fn material(&mut self, m: &Material) -> Result<u64, FeError> {
        let (id, new) = self
            .materials
            .id("MAT1", &[m.youngs_modulus, m.poisson_ratio, m.density]);
        if new {
            self.card(
                "MAT1",
                &[
                    Field::Int(id),
                    Field::Real(m.youngs_modulus),
                    Field::Blank,
                    Field::Real(m.poisson_ratio),
                    Field::Real(m.density),
                ],
            )?;
        }
        Ok(id)
    }

    fn property(
        &mut self,
        card: &str,
        values: &[f64],
        fields: &dyn Fn(u64) -> Vec<Field>,
    ) -> Result<u64, FeError> {
        let (id, new) = self.properties.id(card, values);
        if new {
            self.card(card, &fields(id))?;
        }
        Ok(id)
    }

    fn card(&mut self, name: &str, fields: &[Field]) -> Result<(), FeError> {
        card(&mut self.out, name, fields)
    }
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
                Field::Int(i as u64 + 1),
                Field::Blank,
                Field::Real(p.x),
                Field::Real(p.y),
                Field::Real(p.z),
            ];
            card(&mut self.out, "GRID", &fields)?;
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
            let mut fields = vec![Field::Int(1), Field::components(&mask)?];
            fields.extend(grids.into_iter().map(Field::Int));
            self.card("SPC1", &fields)?;
        }
        Ok(())
    }
}

/// Writes `mesh` as bulk data (BEGIN BULK … ENDDATA): the grids, every entity's cards
/// ([`crate::fe::element::Element::write_bulk`], in the registry's order), the supports.
pub fn write_bulk_deck(mesh: &Mesh) -> Result<String, FeError> {
    if let Some(node) = mesh.displacement_frames.keys().next() {
        return Err(FeError::Mesh(format!(
            "node {node} has a displacement frame (GRID CD); writing displacement frames is not \
             supported"
        )));
    }
    let mut deck = Deck::new(mesh);
    deck.header();
    deck.grids()?;
    for &kind in Entity::ALL {
        let list = kind.of(mesh);
        for i in 0..list.len() {
            list.write_bulk(i, mesh, &mut deck)?;
        }
    }
    deck.spc1()?;
    deck.out.push_str("ENDDATA\n");
    Ok(deck.out)
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
