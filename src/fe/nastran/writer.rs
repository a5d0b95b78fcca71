//! [`Mesh`] → bulk data deck (free field, every number at full precision), so a body built here
//! can be read back, inspected or handed to another solver.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::fe::mesh::{Material, Mesh};
use crate::fe::FeError;

fn num(x: f64) -> String {
    // Rust's shortest round-trip form, with the point Nastran requires.
    let s = format!("{x:e}");
    if s.contains('.') {
        s
    } else {
        s.replacen('e', ".e", 1)
    }
}

/// Ids of distinct materials (by bit pattern).
#[derive(Default)]
struct Materials {
    ids: BTreeMap<[u64; 3], u32>,
    text: String,
}

impl Materials {
    fn id(&mut self, m: &Material) -> u32 {
        let key = [
            m.youngs_modulus.to_bits(),
            m.poisson_ratio.to_bits(),
            m.density.to_bits(),
        ];
        let next = self.ids.len() as u32 + 1;
        *self.ids.entry(key).or_insert_with(|| {
            let _ = writeln!(
                self.text,
                "MAT1,{next},{},,{},{}",
                num(m.youngs_modulus),
                num(m.poisson_ratio),
                num(m.density)
            );
            next
        })
    }
}

/// The deck of `mesh`: GRID ids are node index + 1, element ids count per kind. Named nodes and
/// regions become comments (Nastran has no names).
pub fn write_bulk_deck(mesh: &Mesh) -> Result<String, FeError> {
    let mut out = String::from("$ written by engine_mount_chassis\nBEGIN BULK\n");
    for (name, node) in &mesh.named_nodes {
        let _ = writeln!(out, "$ node {name} = GRID {}", node + 1);
    }
    for (i, p) in mesh.nodes.iter().enumerate() {
        let _ = writeln!(
            out,
            "GRID,{},,{},{},{}",
            i + 1,
            num(p.x),
            num(p.y),
            num(p.z)
        );
    }
    let mut materials = Materials::default();
    let mut body = String::new();
    let mut pid = 0;
    let mut eid = 0;
    for s in &mesh.shells {
        pid += 1;
        eid += 1;
        let mid = materials.id(&s.material);
        let ratio = (s.bending_thickness / s.thickness).powi(3);
        let _ = writeln!(
            body,
            "PSHELL,{pid},{mid},{},{mid},{},,,{}",
            num(s.thickness),
            num(ratio),
            num(s.extra_mass_per_area)
        );
        let [a, b, c, d] = s.nodes.map(|n| n + 1);
        let _ = writeln!(body, "CQUAD4,{eid},{pid},{a},{b},{c},{d}");
    }
    for bm in &mesh.beams {
        pid += 1;
        eid += 1;
        let mid = materials.id(&bm.material);
        let sec = &bm.section;
        let _ = writeln!(
            body,
            "PBAR,{pid},{mid},{},{},{},{},{}",
            num(sec.area),
            num(sec.iz),
            num(sec.iy),
            num(sec.j),
            num(bm.extra_mass_per_length)
        );
        let o = bm.orientation;
        let _ = writeln!(
            body,
            "CBAR,{eid},{pid},{},{},{},{},{}",
            bm.nodes[0] + 1,
            bm.nodes[1] + 1,
            num(o.x),
            num(o.y),
            num(o.z)
        );
    }
    for m in &mesh.masses {
        eid += 1;
        let j = &m.inertia;
        let _ = writeln!(
            body,
            "CONM2,{eid},{},,{},,,,\n+,{},{},{},{},{},{}",
            m.node + 1,
            num(m.mass),
            num(j[(0, 0)]),
            num(-j[(1, 0)]),
            num(j[(1, 1)]),
            num(-j[(2, 0)]),
            num(-j[(2, 1)]),
            num(j[(2, 2)])
        );
    }
    let mut scalar =
        |body: &mut String, card: &str, value: f64, g1: usize, d: usize, g2: Option<usize>| {
            if value == 0.0 {
                return;
            }
            eid += 1;
            let second = g2
                .map(|g| format!(",{},{}", g + 1, d + 1))
                .unwrap_or_default();
            let _ = writeln!(
                body,
                "{card},{eid},{},{},{}{second}",
                num(value),
                g1 + 1,
                d + 1
            );
        };
    for s in &mesh.ground_springs {
        for d in 0..6 {
            scalar(&mut body, "CELAS2", s.stiffness[d], s.node, d, None);
            scalar(&mut body, "CDAMP2", s.damping[d], s.node, d, None);
        }
    }
    for s in &mesh.springs {
        for d in 0..6 {
            scalar(
                &mut body,
                "CELAS2",
                s.stiffness[d],
                s.nodes[0],
                d,
                Some(s.nodes[1]),
            );
            scalar(
                &mut body,
                "CDAMP2",
                s.damping[d],
                s.nodes[0],
                d,
                Some(s.nodes[1]),
            );
        }
    }
    let mut by_node: BTreeMap<usize, String> = BTreeMap::new();
    for (n, d) in &mesh.constraints {
        by_node
            .entry(*n)
            .or_default()
            .push_str(&(d + 1).to_string());
    }
    for (n, dofs) in by_node {
        let _ = writeln!(body, "SPC1,1,{dofs},{}", n + 1);
    }
    out.push_str(&materials.text);
    out.push_str(&body);
    out.push_str("ENDDATA\n");
    Ok(out)
}
