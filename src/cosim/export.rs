//! What an instance writes for the analyses above the simulation (transfer paths, transfer
//! functions, operating deflection shapes, the mount decoupling table), when asked to at its
//! initialisation: the modal data of the body it simulates and the model linearised at its
//! static equilibrium, from the model itself, so an analysis can never use a second copy that
//! drifts from what was simulated.
//!
//! Files, in the folder named by the request (created if missing; each file written to a
//! temporary name and renamed into place):
//! - `manifest.json`: format and version, the FMU, the scene, which body point each mount acts
//!   on, and which of the files below were written;
//! - `body.json`: the reduced body as the model uses it (the [`ReducedChassis`]: frequencies
//!   `omega` in rad/s, damping ratios `zeta`, the named points with their mode-shape rows), for
//!   the elastic body (engine scene 2 and the body FMU);
//! - `powertrain.json` (engine FMU): the powertrain as one rigid body on its mounts at the static
//!   equilibrium ([`RigidPowertrain`]) and every natural mode with its decoupling-table row;
//! - `linear.json` (engine FMU): the state-space model `A, B, C, D` ([`Linearisation`]);
//! - with full recovery, `mesh.json` and `shapes.npy`: the body's nodes and cells and its modes
//!   on every node (NumPy array `[node, dof, mode]`, little-endian f64), recovered for this
//!   export only and dropped afterwards ([`crate::cms::recover_all_nodes`]).

use std::io::Write;
use std::path::Path;

use faer::Mat;
use serde::Serialize;
use serde_json::json;

use super::body::BodySimulation;
use super::scene::vehicle_config;
use super::settings::ExportRequest;
use super::{Error, Settings, Simulation};
use crate::cms::{recover_all_nodes, ReducedChassis};
use crate::model::coupled::{Linearisation, MountTarget, RigidPowertrain};
use crate::model::scene::reduction_spec;
use crate::model::{Mode, ModeKind};

/// Version of the folder's layout; a reader refuses another.
pub const EXPORT_VERSION: u32 = 1;

fn io_error(path: &Path, e: std::io::Error) -> Error {
    Error::Model(format!("analysis export: {}: {e}", path.display()))
}

/// Writes `bytes` as `folder/name`, through a temporary file renamed into place.
fn write_file(folder: &Path, name: &str, bytes: &[u8]) -> Result<(), Error> {
    let path = folder.join(name);
    let partial = folder.join(format!(".{name}.{}.part", std::process::id()));
    let mut file = std::fs::File::create(&partial).map_err(|e| io_error(&partial, e))?;
    file.write_all(bytes).map_err(|e| io_error(&partial, e))?;
    drop(file);
    std::fs::rename(&partial, &path).map_err(|e| io_error(&path, e))
}

fn write_json(folder: &Path, name: &str, value: &impl Serialize) -> Result<(), Error> {
    let text = serde_json::to_string(value)
        .map_err(|e| Error::Model(format!("analysis export: {name}: {e}")))?;
    write_file(folder, name, text.as_bytes())
}

/// A NumPy `.npy` file (format 1.0) of little-endian f64 in C order.
pub fn npy(shape: &[usize], data: &[f64]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let dims = if dims.len() == 1 {
        format!("{},", dims[0])
    } else {
        dims.join(", ")
    };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({dims}), }}");
    // Magic (6) + version (2) + length (2) + header + '\n', padded to a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for x in data {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

fn rows(m: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect()
}

fn matrix<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>) -> Vec<Vec<f64>> {
    (0..R)
        .map(|i| (0..C).map(|j| m[(i, j)]).collect())
        .collect()
}

fn vector(v: &nalgebra::Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn mode_record(mode: &Mode) -> serde_json::Value {
    let (kind, direction) = match &mode.kind {
        ModeKind::RigidBody(d) => ("rigid", Some(format!("{d:?}").to_lowercase())),
        ModeKind::RingCarrier { direction, .. } => (
            "ring_carrier",
            Some(format!("{direction:?}").to_lowercase()),
        ),
        ModeKind::Body { .. } => ("body", None),
    };
    json!({
        "frequency_hz": mode.frequency_hz,
        "damping_ratio": mode.damping_ratio,
        "kind": kind,
        "direction": direction,
        "description": mode.description,
        "powertrain_fraction": mode.powertrain_fraction,
        "mount_strain_fraction": mode.mount_strain_fraction,
        "directions_at_centre_of_mass": mode.centre_of_mass_directions,
    })
}

fn powertrain_record(
    rigid: &RigidPowertrain,
    modes: &[Mode],
    housing: &nalgebra::Vector3<f64>,
) -> serde_json::Value {
    let axis = |a: &crate::model::coupled::Axis| json!({"point": vector(&a.point), "direction": vector(&a.direction)});
    json!({
        "directions": ["x", "y", "z", "rx", "ry", "rz"],
        "centre_of_mass": vector(&rigid.centre_of_mass),
        "housing_centre_of_mass": vector(housing),
        "mass": matrix(&rigid.mass),
        "stiffness": matrix(&rigid.stiffness),
        "crank_axis": vector(&rigid.crank_axis),
        "torque_roll_axis": axis(&rigid.torque_roll_axis),
        "elastic_axis": axis(&rigid.elastic_axis),
        "axis_angle_deg": rigid.axis_angle().to_degrees(),
        "axis_offset_m": rigid.axis_offset(),
        "mounts": rigid.mounts.iter().map(|m| json!({
            "mount": m.index + 1,
            "name": m.name,
            "bracket": vector(&m.bracket),
            "body_point": m.body_point,
            "stiffness": matrix(&m.stiffness),
            "damping": matrix(&m.damping),
            "force": vector(&m.force),
        })).collect::<Vec<_>>(),
        "modes": modes.iter().map(mode_record).collect::<Vec<_>>(),
    })
}

fn linear_record(l: &Linearisation) -> serde_json::Value {
    json!({
        "states": l.states,
        "inputs": l.inputs,
        "outputs": l.outputs,
        "a": rows(&l.a),
        "b": rows(&l.b),
        "c": rows(&l.c),
        "d": rows(&l.d),
    })
}

/// The body's modes on every node, written as `mesh.json` and `shapes.npy`; returns the node
/// count.
fn write_full_recovery(
    folder: &Path,
    settings: &Settings,
    body: &ReducedChassis,
) -> Result<usize, Error> {
    let vehicle = vehicle_config(settings)?;
    let (spec, _) = reduction_spec(&vehicle, &settings.chassis).map_err(|e| {
        Error::Model(format!(
            "analysis export: full recovery needs the body's mesh ({e}); only the named \
             points' rows of a body reduced elsewhere are known"
        ))
    })?;
    let full = recover_all_nodes(&spec, body)
        .map_err(|e| Error::Model(format!("analysis export: {e}")))?;
    let cells: serde_json::Map<String, serde_json::Value> = full
        .cells
        .iter()
        .map(|(kind, c)| (kind.to_string(), json!(c)))
        .collect();
    write_json(
        folder,
        "mesh.json",
        &json!({"nodes": full.nodes, "cells": cells, "mode_descriptions": full.descriptions}),
    )?;
    write_file(
        folder,
        "shapes.npy",
        &npy(&[full.nodes.len(), 6, full.modes], &full.shapes),
    )?;
    Ok(full.nodes.len())
}

/// What was written, for the log.
struct Written {
    files: Vec<&'static str>,
    notes: Vec<String>,
}

fn engine(
    folder: &Path,
    request: &ExportRequest,
    settings: &Settings,
    sim: &Simulation,
) -> Result<(Written, serde_json::Value), Error> {
    let model = sim.linearisation_model()?;
    let y = &sim.equilibrium;
    let mut written = Written {
        files: Vec::new(),
        notes: Vec::new(),
    };
    let mount_points: Vec<Option<String>> = model
        .mounts()
        .iter()
        .map(|m| match m.as_ref().map(|m| m.target) {
            Some(MountTarget::BodyPoint(p)) => Some(model.body().points[p].name.clone()),
            _ => None,
        })
        .collect();
    if model.body().n_modes() > 0 {
        write_json(folder, "body.json", model.body())?;
        written.files.push("body.json");
    }
    let modes = model.modes(y)?;
    let rigid = model.rigid_powertrain(y)?;
    write_json(
        folder,
        "powertrain.json",
        &powertrain_record(&rigid, &modes, &model.powertrain().housing_reference()),
    )?;
    written.files.push("powertrain.json");
    let linear = model.linearise(y)?;
    written.notes.push(format!(
        "{} states, {} outputs",
        linear.states.len(),
        linear.outputs.len()
    ));
    write_json(folder, "linear.json", &linear_record(&linear))?;
    written.files.push("linear.json");
    if request.full_recovery {
        if model.body().n_modes() == 0 {
            return Err(Error::Model(
                "analysis export: full recovery needs the elastic body (scene 2)".into(),
            ));
        }
        let nodes = write_full_recovery(folder, settings, model.body())?;
        written.files.extend(["mesh.json", "shapes.npy"]);
        written.notes.push(format!("modes on {nodes} nodes"));
    }
    Ok((written, json!(mount_points)))
}

fn body_alone(
    folder: &Path,
    request: &ExportRequest,
    settings: &Settings,
    sim: &BodySimulation,
) -> Result<(Written, serde_json::Value), Error> {
    let model = sim.model();
    let body = model.body();
    write_json(folder, "body.json", body)?;
    let mut written = Written {
        files: vec!["body.json"],
        notes: Vec::new(),
    };
    if request.full_recovery {
        let nodes = write_full_recovery(folder, settings, body)?;
        written.files.extend(["mesh.json", "shapes.npy"]);
        written.notes.push(format!("modes on {nodes} nodes"));
    }
    let mount_points: Vec<Option<String>> = model
        .mount_points()
        .iter()
        .map(|p| p.map(|p| body.points[p].name.clone()))
        .collect();
    Ok((written, json!(mount_points)))
}

/// Writes the export of the engine simulation `sim` built from `settings`; returns a line for
/// the log.
pub fn write_engine(
    sim: &Simulation,
    settings: &Settings,
    request: &ExportRequest,
) -> Result<String, Error> {
    let folder = create_folder(request)?;
    let (written, mount_points) = engine(folder, request, settings, sim)?;
    finish(
        folder,
        written,
        mount_points,
        "engine",
        Some(settings.scene.number()),
    )
}

/// Writes the export of the body alone `sim` built from `settings`; returns a line for the log.
pub fn write_body(
    sim: &BodySimulation,
    settings: &Settings,
    request: &ExportRequest,
) -> Result<String, Error> {
    let folder = create_folder(request)?;
    let (written, mount_points) = body_alone(folder, request, settings, sim)?;
    finish(folder, written, mount_points, "body", None)
}

fn create_folder(request: &ExportRequest) -> Result<&Path, Error> {
    let folder = &request.folder;
    std::fs::create_dir_all(folder).map_err(|e| io_error(folder, e))?;
    Ok(folder)
}

/// Writes the manifest of what was `written` and returns the line for the log.
fn finish(
    folder: &Path,
    written: Written,
    mount_points: serde_json::Value,
    fmu: &str,
    scene: Option<i32>,
) -> Result<String, Error> {
    write_json(
        folder,
        "manifest.json",
        &json!({
            "format": "engine_mount_chassis analysis export",
            "version": EXPORT_VERSION,
            "crate_version": env!("CARGO_PKG_VERSION"),
            "fmu": fmu,
            "scene": scene,
            "mount_points": mount_points,
            "files": written.files,
        }),
    )?;
    Ok(format!(
        "analysis export written to {}: {}{}",
        folder.display(),
        written.files.join(", "),
        if written.notes.is_empty() {
            String::new()
        } else {
            format!(" ({})", written.notes.join("; "))
        }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_is_aligned_and_names_the_shape() {
        let bytes = npy(&[2, 3], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
        assert!(header.contains("'shape': (2, 3)") && header.ends_with('\n'));
        assert_eq!(bytes.len(), 10 + len + 48);
        let last = f64::from_le_bytes(bytes[bytes.len() - 8..].try_into().unwrap());
        assert_eq!(last, 6.0);
        let one = npy(&[4], &[0.0; 4]);
        let len = u16::from_le_bytes([one[8], one[9]]) as usize;
        assert!(std::str::from_utf8(&one[10..10 + len])
            .unwrap()
            .contains("(4,)"));
    }
}
