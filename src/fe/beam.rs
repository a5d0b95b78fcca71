//! Two-node 3D beam (Timoshenko, Euler-Bernoulli when rigid in shear): stiffness and HRZ-lumped
//! mass in global axes, with Nastran's end conditions ([`BeamEnds`]): pin flags released by
//! static condensation in element axes, then rigid offsets from the nodes to the element ends.
//!
//! Bending in each element plane uses the exact stiffness of a uniform prismatic member with
//! transverse shear deformation (Przemieniecki, *Theory of Matrix Structural Analysis*, 1968,
//! §5.6; the form of Nastran's CBAR): with φ = 12 E I / (k A G L²),
//! k_vv = 12 E I / ((1 + φ) L³), k_vθ = 6 E I / ((1 + φ) L²), k_θθ = (4 + φ) E I / ((1 + φ) L)
//! at the same end and (2 − φ) E I / ((1 + φ) L) across the element. k is the section's shear
//! area factor of that plane ([`crate::fe::mesh::BeamSection`] `shear_factor_y` for the x-y
//! plane with `iz`, Nastran's K1/I1 of plane 1; `shear_factor_z` for x-z with `iy`, K2/I2); no
//! factor is φ = 0, the Euler-Bernoulli matrix bit for bit. The element reproduces a cantilever's
//! tip deflection P L³/(3 E I) + P L/(k A G) with any number of elements.
//!
//! The bulk-data reader takes k from PBAR/PBEAM K1, K2 as Nastran defines them: shear stiffness
//! K1·A·G in plane 1, K2·A·G in plane 2. PBAR: blank is infinite (shear flexibility neglected;
//! Autodesk Nastran reference, PBAR remark 4) and 0.0 is read as infinite as well (Altair
//! OptiStruct PBAR comments). PBEAM: blank is 1.0, and 0.0 sets the shear flexibility to zero,
//! "to obtain the Bernoulli-Euler beam theory" (MSC Nastran 2022.4 Quick Reference Guide, PBEAM
//! remarks 8 and 12).
//!
//! The mass does not depend on the shear factors: the HRZ lumping below (bending rotary inertia
//! from the Euler-Bernoulli consistent matrix) is kept, so a shear-flexible section changes K
//! alone. Nastran's diagonal mass (PARAM,COUPMASS off) is likewise the scaled diagonal of its
//! coupled matrix, rotary inertia included (Autodesk Nastran reference, PARAM COUPMASS); whether
//! its coupled CBAR mass carries shear terms is not documented there.
//!
//! With offsets the element runs between the offset ends p₁ + w₁ and p₂ + w₂ (its axis, length
//! and orientation come from them); each end moves rigidly with its node, u_end = u + θ × w,
//! so K_node = Tᵀ K_end T with T = \[I −\[w\]×; 0 I\] per end, and likewise for the mass,
//! which stays lumped at the element ends (the offset arm carries the lever-arm coupling).
//!
//! A pin flag releases element DOFs at an end: the released DOFs are condensed out one at a
//! time (K ← K − K·ᵢ Kᵢ· / Kᵢᵢ) from the shear-flexible element stiffness; a released DOF left
//! without stiffness by earlier releases (axial released at both ends, say) is dropped, as
//! NASTRAN does, so a beam that becomes a mechanism on its own still assembles and carries what
//! it still can. The lumped mass does not depend on the pin flags (Nastran's lumped mass does
//! not either).

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::element::{BulkWriter, CheckLimits, Element, ElementMatrices, Field, Finding};
use super::error::{require_non_negative, require_positive, FeError};
use super::mesh::{Beam, BeamEnds, Mesh};

/// 12 × 12 element matrix, DOF order (ux uy uz rx ry rz) at node 1 then node 2.
pub type Mat12 = SMatrix<f64, 12, 12>;

/// Local frame of a beam: rows are the local x (axis), y and z unit vectors in global axes.
pub fn local_frame(
    index: usize,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
    orientation: &Vector3<f64>,
) -> Result<(Matrix3<f64>, f64), FeError> {
    let axis = p2 - p1;
    let length = axis.norm();
    if !(length.is_finite() && length > 1e-9) {
        return Err(FeError::Mesh(format!(
            "beam {index}: zero or non-finite length {length}"
        )));
    }
    let ex = axis / length;
    let ez = ex.cross(orientation);
    let ez_norm = ez.norm();
    if !(ez_norm.is_finite() && ez_norm > 1e-6 * orientation.norm().max(1e-300)) {
        return Err(FeError::Mesh(format!(
            "beam {index}: orientation vector {:?} is parallel to the axis or zero",
            orientation.as_slice()
        )));
    }
    let ez = ez / ez_norm;
    let ey = ez.cross(&ex);
    let r = Matrix3::from_rows(&[ex.transpose(), ey.transpose(), ez.transpose()]);
    Ok((r, length))
}

/// T with u_element_axes = T u_nodes: the rigid offset arms (u_end = u − \[w\]× θ), then the
/// rotation into element axes.
fn end_transform(r: &Matrix3<f64>, offsets: &[Vector3<f64>; 2]) -> Mat12 {
    let mut t = Mat12::zeros();
    for (end, w) in offsets.iter().enumerate() {
        let o = 6 * end;
        t.fixed_view_mut::<3, 3>(o, o).copy_from(r);
        t.fixed_view_mut::<3, 3>(o + 3, o + 3).copy_from(r);
        t.fixed_view_mut::<3, 3>(o, o + 3)
            .copy_from(&(-(r * w.cross_matrix())));
    }
    t
}

/// Static condensation of the released DOFs (indices 0..12 in element axes), one at a time.
fn release(k: &mut Mat12, pins: &[[bool; 6]; 2]) {
    let original: Vec<f64> = (0..12).map(|i| k[(i, i)]).collect();
    for i in (0..12).filter(|&i| pins[i / 6][i % 6]) {
        let kii = k[(i, i)];
        // A DOF whose stiffness earlier releases took away is a mechanism of the element:
        // nothing to condense, it just carries nothing (NASTRAN zeroes it the same way).
        if kii > 1e-9 * original[i] {
            let col = k.column(i).into_owned();
            *k -= col * col.transpose() / kii;
        }
        k.row_mut(i).fill(0.0);
        k.column_mut(i).fill(0.0);
    }
}

fn validate(index: usize, beam: &Beam) -> Result<(), FeError> {
    let s = &beam.section;
    let m = &beam.material;
    let name = |f: &str| format!("beam {index}: {f}");
    require_positive(&name("area"), s.area)?;
    require_positive(&name("iy"), s.iy)?;
    require_positive(&name("iz"), s.iz)?;
    require_positive(&name("j"), s.j)?;
    require_positive(&name("youngs_modulus"), m.youngs_modulus)?;
    require_non_negative(&name("density"), m.density)?;
    require_non_negative(&name("extra_mass_per_length"), beam.extra_mass_per_length)?;
    for (k, what) in [
        (s.shear_factor_y, "shear_factor_y"),
        (s.shear_factor_z, "shear_factor_z"),
    ] {
        if let Some(k) = k {
            require_positive(&name(what), k)?;
        }
    }
    if !(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
        return Err(FeError::InvalidInput(format!(
            "beam {index}: poisson_ratio must be in (-1, 0.5), got {}",
            m.poisson_ratio
        )));
    }
    Ok(())
}

/// Global stiffness matrix of `beam` with end points `p1`, `p2`.
pub fn stiffness(
    index: usize,
    beam: &Beam,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
) -> Result<Mat12, FeError> {
    stiffness_with_ends(index, beam, &BeamEnds::default(), p1, p2)
}

/// Global lumped mass matrix of `beam` with end points `p1`, `p2`.
pub fn lumped_mass(
    index: usize,
    beam: &Beam,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
) -> Result<Mat12, FeError> {
    lumped_mass_with_ends(index, beam, &BeamEnds::default(), p1, p2)
}

/// Element frame and length between the offset ends.
fn frame_between_ends(
    index: usize,
    beam: &Beam,
    ends: &BeamEnds,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
) -> Result<(Matrix3<f64>, f64), FeError> {
    validate(index, beam)?;
    if ends
        .offsets
        .iter()
        .any(|w| w.iter().any(|c| !c.is_finite()))
    {
        return Err(FeError::InvalidInput(format!(
            "beam {index}: non-finite offset {:?}",
            ends.offsets
        )));
    }
    if ends.pins.iter().any(|p| p.iter().all(|&r| r)) {
        return Err(FeError::InvalidInput(format!(
            "beam {index}: an end releases all six DOFs (Nastran allows at most five pin flags \
             per end)"
        )));
    }
    local_frame(
        index,
        &(p1 + ends.offsets[0]),
        &(p2 + ends.offsets[1]),
        &beam.orientation,
    )
}

/// Global stiffness matrix of `beam` on its nodes at `p1`, `p2` with offsets and pin flags
/// `ends` (see the module documentation).
pub fn stiffness_with_ends(
    index: usize,
    beam: &Beam,
    ends: &BeamEnds,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
) -> Result<Mat12, FeError> {
    let (r, l) = frame_between_ends(index, beam, ends, p1, p2)?;
    let e = beam.material.youngs_modulus;
    let g = beam.material.shear_modulus();
    let s = &beam.section;
    let mut k = Mat12::zeros();
    let mut put = |i: usize, j: usize, v: f64| {
        k[(i, j)] += v;
        if i != j {
            k[(j, i)] += v;
        }
    };
    let ea = e * s.area / l;
    put(0, 0, ea);
    put(6, 6, ea);
    put(0, 6, -ea);
    let gj = g * s.j / l;
    put(3, 3, gj);
    put(9, 9, gj);
    put(3, 9, -gj);
    // φ = 12 E I / (k A G L²); rigid in shear (no factor) is φ = 0, Euler-Bernoulli.
    let phi = |i: f64, k: Option<f64>| k.map_or(0.0, |k| 12.0 * e * i / (k * s.area * g * l * l));
    // One bending plane with its translation, rotation DOFs [v₁, θ₁, v₂, θ₂]: the exact
    // stiffness of a uniform Timoshenko member. With φ = 0 every term divides by exactly 1, so
    // a section rigid in shear gives the Euler-Bernoulli matrix bit for bit.
    let bend = |put: &mut dyn FnMut(usize, usize, f64),
                [v1, t1, v2, t2]: [usize; 4],
                sign: f64,
                ei: f64,
                phi: f64| {
        let d = 1.0 + phi;
        put(v1, v1, 12.0 * ei / l.powi(3) / d);
        put(v1, t1, sign * 6.0 * ei / l.powi(2) / d);
        put(v1, v2, -12.0 * ei / l.powi(3) / d);
        put(v1, t2, sign * 6.0 * ei / l.powi(2) / d);
        put(t1, t1, (4.0 + phi) * ei / l / d);
        put(t1, v2, -sign * 6.0 * ei / l.powi(2) / d);
        put(t1, t2, (2.0 - phi) * ei / l / d);
        put(v2, v2, 12.0 * ei / l.powi(3) / d);
        put(v2, t2, -sign * 6.0 * ei / l.powi(2) / d);
        put(t2, t2, (4.0 + phi) * ei / l / d);
    };
    // Bending in the local x-y plane (Nastran's plane 1, I1, K1): v and rz.
    bend(
        &mut put,
        [1, 5, 7, 11],
        1.0,
        e * s.iz,
        phi(s.iz, s.shear_factor_y),
    );
    // Bending in the local x-z plane (plane 2, I2, K2): w and ry (a positive ry tilts the axis
    // downwards, hence the opposite sign of the v-θ coupling).
    bend(
        &mut put,
        [2, 4, 8, 10],
        -1.0,
        e * s.iy,
        phi(s.iy, s.shear_factor_z),
    );
    release(&mut k, &ends.pins);
    let t = end_transform(&r, &ends.offsets);
    Ok(t.transpose() * k * t)
}

/// Global lumped mass matrix of `beam` on its nodes at `p1`, `p2` with offsets `ends`.
/// Translations carry half the mass per element end; the torsional inertia is the section's
/// polar moment; the bending rotations get the HRZ diagonal scaling of the consistent matrix
/// (m L² / 78 per end), which keeps the lumped beam accurate for bending. The element length is
/// the distance between the offset ends.
pub fn lumped_mass_with_ends(
    index: usize,
    beam: &Beam,
    ends: &BeamEnds,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
) -> Result<Mat12, FeError> {
    let (r, l) = frame_between_ends(index, beam, ends, p1, p2)?;
    let rho = beam.material.density;
    let s = &beam.section;
    let m = (rho * s.area + beam.extra_mass_per_length) * l;
    let torsion = (rho * (s.iy + s.iz) * l / 2.0).max(1e-12 * m * l * l);
    let bending = m * l * l / 78.0;
    let mut local = Mat12::zeros();
    for node in 0..2 {
        let o = 6 * node;
        for d in 0..3 {
            local[(o + d, o + d)] = m / 2.0;
        }
        local[(o + 3, o + 3)] = torsion;
        local[(o + 4, o + 4)] = bending;
        local[(o + 5, o + 5)] = bending;
    }
    let t = end_transform(&r, &ends.offsets);
    Ok(t.transpose() * local * t)
}

impl Element for Beam {
    const NAME: &'static str = "beam";

    fn nodes(&self) -> Vec<usize> {
        self.nodes.to_vec()
    }

    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        let what = format!("beam {index}");
        let [p1, p2] = mesh.positions(&what, &self.nodes)?;
        let ends = mesh.beam_ends.get(&index).copied().unwrap_or_default();
        Ok(ElementMatrices::stiffness_and_mass(
            &stiffness_with_ends(index, self, &ends, &p1, &p2)?,
            &lumped_mass_with_ends(index, self, &ends, &p1, &p2)?,
        ))
    }

    fn check_shape(
        &self,
        index: usize,
        mesh: &Mesh,
        points: &[Vector3<f64>],
        limits: &CheckLimits,
    ) -> Vec<Finding> {
        // With offsets the element runs between the offset ends, not the nodes.
        let w = mesh
            .beam_ends
            .get(&index)
            .map_or([Vector3::zeros(); 2], |e| e.offsets);
        let (p1, p2) = (points[0] + w[0], points[1] + w[1]);
        if self.nodes[0] == self.nodes[1] || (p2 - p1).norm() < limits.min_beam_length {
            vec![Finding::Wrong(format!(
                "degenerate (length {:.3e} m)",
                (p2 - p1).norm()
            ))]
        } else if (p2 - p1).normalize().cross(&self.orientation).norm()
            < 1e-6 * self.orientation.norm().max(1e-300)
        {
            vec![Finding::Wrong(
                "orientation vector parallel to the axis or zero".into(),
            )]
        } else {
            Vec::new()
        }
    }

    /// A CBAR with its PBAR; offsets and pin flags on the CBAR (OFFT blank, GGG: the grids are
    /// written in basic, so their displacement systems are basic too).
    fn write_bulk(
        &self,
        index: usize,
        mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let mid = deck.material(&self.material)?;
        let s = &self.section;
        let nsm = self.extra_mass_per_length;
        // PBAR K1/K2 = 0.0 reads back as rigid in shear, the same as blank.
        let k = [s.shear_factor_y, s.shear_factor_z].map(|k| k.unwrap_or(0.0));
        let values = [mid as f64, s.area, s.iz, s.iy, s.j, nsm, k[0], k[1]];
        let pid = deck.property("PBAR", &values, &|pid| {
            let mut fields = vec![
                Field::Int(pid),
                Field::Int(mid),
                Field::Real(s.area),
                Field::Real(s.iz),
                Field::Real(s.iy),
                Field::Real(s.j),
                Field::Real(nsm),
            ];
            if k.iter().any(|&k| k != 0.0) {
                // Field 9 and the stress recovery points C1 … F2 stay blank.
                fields.extend((0..9).map(|_| Field::Blank));
                fields.extend([Field::Real(k[0]), Field::Real(k[1])]);
            }
            fields
        })?;
        let what = format!("beam {index}");
        let mut fields = vec![
            deck.element_id(),
            Field::Int(pid),
            deck.grid(&what, self.nodes[0])?,
            deck.grid(&what, self.nodes[1])?,
            Field::Real(self.orientation.x),
            Field::Real(self.orientation.y),
            Field::Real(self.orientation.z),
        ];
        if let Some(ends) = mesh.beam_ends.get(&index) {
            fields.push(Field::Blank);
            for pins in ends.pins {
                fields.push(Field::components(&pins).unwrap_or(Field::Blank));
            }
            for w in ends.offsets {
                fields.extend(w.iter().map(|&c| Field::Real(c)));
            }
        }
        deck.card("CBAR", &fields)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::mesh::{BeamSection, Material};
    use crate::fe::test_support::rigid_motion;

    fn beam_along(orientation: Vector3<f64>) -> Beam {
        Beam {
            nodes: [0, 1],
            material: Material::STEEL,
            section: BeamSection::box_tube(0.04, 0.06, 0.002),
            orientation,
            extra_mass_per_length: 0.0,
        }
    }

    #[test]
    fn rigid_body_motions_cost_no_energy_for_a_skew_beam() {
        let p1 = Vector3::new(0.1, -0.2, 0.3);
        let p2 = Vector3::new(0.9, 0.4, -0.1);
        let mut shear_flexible = beam_along(Vector3::new(0.0, 0.0, 1.0));
        shear_flexible.section.shear_factor_y = Some(0.4);
        shear_flexible.section.shear_factor_z = Some(0.7);
        for b in [beam_along(Vector3::new(0.0, 0.0, 1.0)), shear_flexible] {
            rigid_motions_are_free(&stiffness(0, &b, &p1, &p2).unwrap(), &p1, &p2);
        }
    }

    /// The six rigid-body motions of the nodes at `p1`, `p2` (translations, rotations about the
    /// origin) produce no force.
    fn rigid_motions_are_free(k: &Mat12, p1: &Vector3<f64>, p2: &Vector3<f64>) {
        let scale = k.abs().max();
        for mode in 0..6 {
            let u = SMatrix::<f64, 12, 1>::from_column_slice(&rigid_motion(&[*p1, *p2], mode));
            assert!(
                (k * u).norm() < 1e-9 * scale,
                "rigid mode {mode} strains the beam"
            );
        }
    }

    #[test]
    fn a_negative_or_non_finite_shear_factor_is_refused() {
        let p1 = Vector3::zeros();
        let p2 = Vector3::new(1.0, 0.0, 0.0);
        for k in [-0.5, 0.0, f64::NAN] {
            let mut b = beam_along(Vector3::new(0.0, 1.0, 0.0));
            b.section.shear_factor_z = Some(k);
            let err = stiffness(2, &b, &p1, &p2).unwrap_err().to_string();
            assert!(err.contains("beam 2: shear_factor_z"), "{err}");
        }
    }

    #[test]
    fn offsets_and_pins_keep_rigid_body_motions_free_and_released_ends_unloaded() {
        let p1 = Vector3::new(0.1, -0.2, 0.3);
        let p2 = Vector3::new(0.9, 0.4, -0.1);
        let ends = BeamEnds {
            offsets: [
                Vector3::new(0.0, 0.05, -0.02),
                Vector3::new(0.03, 0.0, 0.04),
            ],
            pins: [[false, false, false, false, true, true], [false; 6]],
        };
        let b = beam_along(Vector3::new(0.0, 0.0, 1.0));
        let k = stiffness_with_ends(0, &b, &ends, &p1, &p2).unwrap();
        let scale = k.abs().max();
        assert!((k - k.transpose()).abs().max() < 1e-12 * scale);
        rigid_motions_are_free(&k, &p1, &p2);
        // Any node motion leaves no bending moment at the released end A: the element-axes
        // forces at the end, T u with K in element axes, have zero ry and rz components.
        let (r, _) = local_frame(
            0,
            &(p1 + ends.offsets[0]),
            &(p2 + ends.offsets[1]),
            &b.orientation,
        )
        .unwrap();
        let t_inv = end_transform(&r, &ends.offsets).try_inverse().unwrap();
        let k_local = t_inv.transpose() * k * t_inv;
        for j in 0..12 {
            assert!(k_local[(4, j)].abs() < 1e-9 * scale && k_local[(5, j)].abs() < 1e-9 * scale);
        }
        let mut all = ends;
        all.pins[1] = [true; 6];
        let err = stiffness_with_ends(3, &b, &all, &p1, &p2)
            .unwrap_err()
            .to_string();
        assert!(err.contains("beam 3") && err.contains("six"), "{err}");
    }

    #[test]
    fn parallel_orientation_is_reported_with_the_beam_index() {
        let p1 = Vector3::zeros();
        let p2 = Vector3::new(1.0, 0.0, 0.0);
        let err = stiffness(7, &beam_along(Vector3::new(2.0, 0.0, 0.0)), &p1, &p2).unwrap_err();
        assert!(err.to_string().contains("beam 7"));
    }

    #[test]
    fn lumped_mass_has_the_element_mass_per_direction() {
        let b = beam_along(Vector3::new(0.0, 1.0, 1.0));
        let p1 = Vector3::zeros();
        let p2 = Vector3::new(0.3, 0.4, 0.0);
        let m = lumped_mass(0, &b, &p1, &p2).unwrap();
        let expected = b.material.density * b.section.area * 0.5;
        for d in 0..3 {
            assert!((m[(d, d)] + m[(6 + d, 6 + d)] - expected).abs() < 1e-12 * expected);
        }
    }
}
