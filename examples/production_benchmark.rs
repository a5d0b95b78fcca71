//! Production-size benchmark: many modes and million-DOF bulk decks.
//!
//! `cargo run --release --example production_benchmark -- modes`
//!   (a) The fixed-interface eigenproblem of the default body (4 mounts × 3 translations held)
//!   for cut-offs of 225 Hz, 500 Hz, 1 kHz and 2 kHz: the single-shift Lanczos solver
//!   (`eigen::lowest_modes`, given the exact mode count from a Sturm count, so without the
//!   retries the reduction used to need) against spectrum slicing
//!   (`eigen::slicing::sliced_modes`), time and largest frequency difference.
//!
//! `cargo run --release --example production_benchmark -- sizes [refinements…] [--modes N]`
//!   (b) For each refinement r (default 1 2 4 8: grid spacing / r, about 15 k, 60 k, 240 k and
//!   950 k DOF) the procedural body is written as a multi-file bulk deck (`main.bdf` with
//!   `INCLUDE`s of `grids.bdf`, `shells.bdf` — the floor panels with ZOFFS = −t/2 —,
//!   `properties.bdf`, `beams_masses_links.bdf` — the sills with 3 cm CBAR offsets —,
//!   `welds.bdf`: CBUSH spot welds across every 40th shell's diagonal, and `brackets.bdf`: a
//!   steel block of 2 × 2 × 2 CHEXA under each engine mount node, hung on it by an RBE2) by one
//!   child process. A second child process reads it with the streaming reader alone, then goes
//!   from the file to a running FMU: it loads the FMU's binary (`cargo build --release` makes
//!   it; the FMU tests' host drives it), points `configFile` at a vehicle JSON naming the deck
//!   (scene 2, cache off), initialises (the FMU reads and reduces the deck — default 225 Hz
//!   cut-off — and finds the static equilibrium) and makes 100 `fmi2DoStep`s of 1 ms at
//!   1800 rpm. Its peak resident memory (VmHWM) is the one reported. Growth exponents are
//!   log-log least-squares fits against DOF. With `--modes N` the largest size is also run
//!   keeping N fixed-interface modes (`chassis.maxModes`, a third child process).
//!
//! Internal subcommands (run by `sizes` as child processes): `write <r> <dir>`,
//! `run <r> <dir> <cutoff_hz|0> <modes|0>`.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::{region, Chassis, MountLayout};
use engine_mount_chassis::cms::{InterfaceDofs, Partition};
use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::eigen::slicing::{eigenvalue_count, sliced_modes, SliceStop};
use engine_mount_chassis::fe::assembly::{assemble, SparseMat};
use engine_mount_chassis::fe::mesh::{Material, Mesh};
use engine_mount_chassis::fe::shell::ShellSection;
use engine_mount_chassis::model::{BodyConfig, VehicleConfig};
use engine_mount_chassis::nastran::{read_bulk_deck_with, write_bulk_deck, DeckOptions};

use fmu_host::{boolean, integer, real, string};
use nalgebra::Vector3;

/// The FMI 2.0 host the FMU tests drive the binary with (dlopen, fmi2 symbols, log capture).
#[path = "../tests/fmi/common/mod.rs"]
mod fmu_host;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn vm_hwm_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("VmHWM:"))?.to_owned();
            line.split_whitespace().nth(1)?.parse::<f64>().ok()
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// CPU time (user + system) of this process so far, s: on a shared machine the wall time
/// depends on the other processes, this does not.
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|w| w.parse().unwrap_or(f64::NAN))
        .collect();
    // Fields 14 and 15 of proc(5), counted from the state (field 3) here; 100 ticks per second.
    (f.get(11).copied().unwrap_or(f64::NAN) + f.get(12).copied().unwrap_or(f64::NAN)) / 100.0
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "n/a".into())
}

/// Rows and columns of `a` not in `interface` (the reduction's own partition).
fn interior(a: &SparseMat, interface: &[usize]) -> SparseMat {
    Partition::new(a.nrows(), interface)
        .and_then(|p| p.interior_block(a, "K or M"))
        .expect("interior block")
}

fn hz(l: &[f64]) -> Vec<f64> {
    l.iter()
        .map(|x| x.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect()
}

fn modes_table() -> Res<()> {
    let chassis = Chassis::build(&ChassisConfig::default())?;
    let asm = assemble(&chassis.mesh)?;
    let ids: Vec<usize> = chassis
        .mount_nodes(MountLayout::Four)?
        .iter()
        .map(|(_, id)| *id)
        .collect();
    let interface = asm
        .dofs
        .indices_of(&ids, InterfaceDofs::Translations.local())?;
    let (k, m) = (interior(&asm.k, &interface), interior(&asm.m, &interface));
    println!(
        "default body: {} DOF, {} interior; load average at start {}",
        asm.dofs.n_free(),
        k.nrows(),
        load()
    );
    println!();
    println!("| cut-off | modes (Sturm count) | single shift (s) | slicing (s) | speed-up | max rel. frequency difference |");
    println!("|---:|---:|---:|---:|---:|---:|");
    for cutoff in [225.0, 500.0, 1000.0, 2000.0] {
        let lambda = (2.0 * std::f64::consts::PI * cutoff).powi(2);
        let (_, count) = eigenvalue_count(&k, &m, lambda)?;
        let t0 = Instant::now();
        let sliced = sliced_modes(&k, &m, 0.0, SliceStop::Upper(lambda))?;
        let t_sliced = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let single = lowest_modes(&k, &m, count, 0.0)?;
        let t_single = t0.elapsed().as_secs_f64();
        let (a, b) = (hz(&single.eigenvalues), hz(&sliced.eigenvalues));
        let diff = if a.len() == b.len() {
            a.iter()
                .zip(&b)
                .map(|(x, y)| (x / y - 1.0).abs())
                .fold(0.0, f64::max)
        } else {
            f64::NAN
        };
        println!(
            "| {cutoff:.0} Hz | {count} (sliced {}) | {t_single:.2} | {t_sliced:.2} | {:.1}x | {diff:.1e} |",
            b.len(),
            t_single / t_sliced
        );
    }
    println!("\nload average at end {}", load());
    Ok(())
}

fn config(r: usize) -> ChassisConfig {
    let mut c = ChassisConfig::default();
    c.geometry.grid_dx /= r as f64;
    c.geometry.grid_dy /= r as f64;
    c.geometry.grid_dz /= r as f64;
    c
}

/// Deck files and the cards each holds (by card name); the rest go to the last part.
fn deck_parts() -> Vec<(&'static str, &'static [&'static str])> {
    vec![
        ("grids.bdf", &["GRID"]),
        ("shells.bdf", &["CQUAD4", "CTRIA3"]),
        (
            "properties.bdf",
            &["PSHELL", "PBAR", "PBEAM", "MAT1", "PBUSH"],
        ),
        ("welds.bdf", &["CBUSH"]),
        ("brackets.bdf", &["CHEXA", "PSOLID"]),
        ("beams_masses_links.bdf", &[]),
    ]
}

/// Writes the body of refinement `r` into `dir` as a multi-file deck; prints GRID ids of the
/// named points as `point <name> <grid>` lines for the parent.
fn write_deck(r: usize, dir: &Path) -> Res<()> {
    let t0 = Instant::now();
    let mut chassis = Chassis::build(&config(r))?;
    let (offset_shells, offset_beams) = add_offsets(&mut chassis.mesh);
    let text = write_bulk_deck(&chassis.mesh)?;
    std::fs::create_dir_all(dir)?;
    let parts = deck_parts();
    let mut bodies: Vec<String> = vec![String::new(); parts.len()];
    let mut header = String::new();
    let mut current = usize::MAX;
    for line in text.lines() {
        if line.starts_with('$') {
            header.push_str(line);
            header.push('\n');
            continue;
        }
        if line == "BEGIN BULK" || line == "ENDDATA" {
            continue;
        }
        if !line.starts_with('*') && !line.starts_with('+') && !line.starts_with(' ') {
            let name = line.split([',', ' ', '*']).next().unwrap_or("");
            current = parts
                .iter()
                .position(|(_, cards)| cards.contains(&name))
                .unwrap_or(parts.len() - 1);
        }
        bodies[current].push_str(line);
        bodies[current].push('\n');
    }
    drop(text);
    // Spot welds: a CBUSH across the diagonal of every 40th shell (stiff translational springs,
    // soft rotational ones, basic axes), as a body-in-white's weld spots tie flange pairs.
    let weld_pid = 9001;
    let _ = writeln!(
        bodies[2],
        "PBUSH,{weld_pid},K,2.0e7,2.0e7,2.0e7,50.,50.,50."
    );
    let mut eid = 9_000_000;
    for s in chassis.mesh.shells.iter().step_by(40) {
        eid += 1;
        let _ = writeln!(
            bodies[3],
            "CBUSH,{eid},{weld_pid},{},{},,,,0",
            s.nodes[0] + 1,
            s.nodes[2] + 1
        );
    }
    let [.., solids, links] = &mut bodies[..] else {
        return Err("deck parts end with the brackets and the links".into());
    };
    let brackets = write_brackets(&chassis, solids, links)?;
    let mut main = header;
    main.push_str("BEGIN BULK\n");
    for ((file, _), body) in parts.iter().zip(&bodies) {
        std::fs::write(dir.join(file), body)?;
        let _ = writeln!(main, "INCLUDE '{file}'");
    }
    main.push_str("ENDDATA\n");
    std::fs::write(dir.join("main.bdf"), main)?;
    let bytes: u64 = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok()?.metadata().ok())
        .map(|m| m.len())
        .sum();
    let vehicle = VehicleConfig::default();
    let mut names: Vec<String> = vehicle
        .mounts
        .iter()
        .filter_map(|m| m.body_node.clone())
        .collect();
    names.extend(vehicle.outputs.iter().cloned());
    for n in names {
        println!("point {n} {}", chassis.node(&n)? + 1);
    }
    println!(
        "written {} nodes {} shells {} welds {:.0} MB {:.1} s {brackets} bracket-hexas \
         {offset_shells} offset-shells {offset_beams} offset-beams",
        chassis.mesh.nodes.len(),
        chassis.mesh.shells.len(),
        eid - 9_000_000,
        bytes as f64 / 1e6,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Offsets as production decks carry them: the floor panels meshed on their upper face (ZOFFS
/// = −t/2 on every floor CQUAD4/CTRIA3, the mid-plane half a thickness below the grids) and the
/// sills' section centroids 3 cm below their grid line (CBAR offsets WA = WB). Returns the numbers
/// of offset shells and beams.
fn add_offsets(mesh: &mut Mesh) -> (usize, usize) {
    let in_region = |name: &str| -> BTreeSet<usize> {
        mesh.regions
            .get(name)
            .map(|nodes| nodes.iter().copied().collect())
            .unwrap_or_default()
    };
    let (floor, sill) = (in_region(region::FLOOR), in_region(region::SILL));
    let offset_sheet = |material: &Material, t: f64, bending_t: f64| {
        Some(Box::new(ShellSection {
            offset: -t / 2.0,
            ..ShellSection::isotropic(material, t, bending_t)
        }))
    };
    let mut shells = 0;
    for s in &mut mesh.shells {
        if s.nodes.iter().all(|n| floor.contains(n)) {
            s.section = offset_sheet(&s.material, s.thickness, s.bending_thickness);
            shells += 1;
        }
    }
    for s in &mut mesh.triangles {
        if s.nodes.iter().all(|n| floor.contains(n)) {
            s.section = offset_sheet(&s.material, s.thickness, s.bending_thickness);
            shells += 1;
        }
    }
    let below = Vector3::new(0.0, 0.0, -0.03);
    let mut beams = 0;
    for (i, b) in mesh.beams.iter().enumerate() {
        if b.nodes.iter().all(|n| sill.contains(n)) {
            let ends = mesh.beam_ends.entry(i).or_default();
            ends.offsets = [below; 2];
            beams += 1;
        }
    }
    (shells, beams)
}

/// Cast mount brackets as production decks carry them: under each engine mount's body node a
/// steel block of 2 × 2 × 2 `CHEXA` (8 cm cube, 27 grids), its top face tied to the mount node by
/// an `RBE2` (solid grids carry translations only, so the bracket hangs on the node through the
/// link). Returns the number of hexahedra written.
fn write_brackets(chassis: &Chassis, solids: &mut String, links: &mut String) -> Res<usize> {
    const SIZE: f64 = 0.08;
    let (pid, mid) = (9101, 9101);
    let _ = writeln!(solids, "MAT1,{mid},2.1e11,,0.3,7850.");
    let _ = writeln!(solids, "PSOLID,{pid},{mid}");
    let (mut grid, mut eid, mut rbe) = (9_500_000u32, 9_600_000u32, 9_700_000u32);
    let mut hexas = 0;
    for m in VehicleConfig::default().mounts {
        let Some(name) = m.body_node else { continue };
        let node = chassis.node(&name)?;
        let p = chassis.mesh.nodes[node];
        let first = grid + 1;
        let id = |i: u32, j: u32, k: u32| first + i + 3 * j + 9 * k;
        for k in 0..3u32 {
            for j in 0..3u32 {
                for i in 0..3u32 {
                    grid += 1;
                    let h = SIZE / 2.0;
                    let _ = writeln!(
                        solids,
                        "GRID,{grid},,{:.6},{:.6},{:.6}",
                        p[0] - h + h * f64::from(i),
                        p[1] - h + h * f64::from(j),
                        p[2] - SIZE + h * f64::from(k)
                    );
                }
            }
        }
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..2 {
                    eid += 1;
                    hexas += 1;
                    let _ = writeln!(
                        solids,
                        "CHEXA,{eid},{pid},{},{},{},{},{},{}\n,{},{}",
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1)
                    );
                }
            }
        }
        rbe += 1;
        let top: Vec<String> = (0..3)
            .flat_map(|j| (0..3).map(move |i| (i, j)))
            .map(|(i, j)| id(i, j, 2).to_string())
            .collect();
        // Free field: eight fields after the name, the rest on a continuation.
        let _ = writeln!(
            links,
            "RBE2,{rbe},{},123,{}\n,{}",
            node + 1,
            top[..5].join(","),
            top[5..].join(",")
        );
    }
    Ok(hexas)
}

fn points_of(dir: &Path) -> Res<BTreeMap<String, u32>> {
    let text = std::fs::read_to_string(dir.join("points.txt"))?;
    let mut points = BTreeMap::new();
    for line in text.lines() {
        let mut w = line.split_whitespace();
        if let (Some("point"), Some(n), Some(g)) = (w.next(), w.next(), w.next()) {
            points.insert(n.to_owned(), g.parse()?);
        }
    }
    Ok(points)
}

/// Reads the deck in `dir` with the streaming reader alone, then loads the FMU's binary (the
/// cdylib `cargo build --release` makes, which `packaging/package.py` puts into the FMU),
/// instantiates it on a vehicle JSON naming the deck, initialises it — the FMU reads the deck,
/// reduces it and finds the static equilibrium — and runs 100 communication steps of 1 ms at
/// 1800 rpm; prints one `result` line.
fn run_deck(dir: &Path, cutoff_hz: f64, modes: usize) -> Res<()> {
    let main = dir.join("main.bdf");
    let t0 = Instant::now();
    let c0 = cpu_s();
    let (body, _) = read_bulk_deck_with(&main, &DeckOptions::default())?;
    let t_read = t0.elapsed().as_secs_f64();
    let c_read = cpu_s() - c0;
    let n_nodes = body.mesh.nodes.len();
    let n_bushes = body.mesh.bushes.len();
    drop(body);
    let hwm_read = vm_hwm_mb();

    let vehicle = VehicleConfig {
        body: BodyConfig::Nastran {
            path: main.clone(),
            points: points_of(dir)?,
            include_root: None,
            damping: None,
        },
        ..VehicleConfig::default()
    };
    let config_file = dir.join("vehicle.json");
    std::fs::write(&config_file, serde_json::to_string_pretty(&vehicle)?)?;

    let fmu = fmu_host::Fmu::load();
    let slave = fmu
        .instantiate_with(
            "benchmark",
            fmu_host::GUID,
            Some(&fmu_host::resources_uri()),
        )
        .ok_or("fmi2Instantiate returned NULL")?;
    let failed = |what: &str| format!("{what} failed: {:?}", slave.logs());
    let ok = |status: u32, what: &str| -> Res<()> {
        if status == fmu_host::OK {
            Ok(())
        } else {
            Err(failed(what).into())
        }
    };
    // Every log category: the FMU's note on the reduced body (modes, range, seconds) is read
    // back from the log below.
    slave.log_everything();
    let config_path = config_file.to_str().ok_or("non-UTF-8 temporary path")?;
    ok(slave.set_integer(&[integer::SCENE], &[2]), "scene")?;
    ok(
        slave.set_string(&[string::CONFIG_FILE], &[config_path]),
        "configFile",
    )?;
    ok(
        slave.set_boolean(&[boolean::CHASSIS_CACHE_ENABLED], &[false]),
        "chassis.cacheEnabled",
    )?;
    ok(
        slave.set_real(&[real::CHASSIS_MODE_CUTOFF], &[cutoff_hz]),
        "chassis.modeCutoff",
    )?;
    ok(
        slave.set_integer(&[integer::CHASSIS_MAX_MODES], &[i32::try_from(modes)?]),
        "chassis.maxModes",
    )?;
    ok(slave.set_real(&[real::RPM], &[1800.0]), "rpm")?;
    ok(slave.setup(0.0, None), "fmi2SetupExperiment")?;
    let t0 = Instant::now();
    let c0 = cpu_s();
    ok(slave.enter_init(), "fmi2EnterInitializationMode")?;
    ok(slave.exit_init(), "fmi2ExitInitializationMode")?;
    let t_init = t0.elapsed().as_secs_f64();
    let c_init = cpu_s() - c0;
    // "…: <n> modes, <lowest>..<highest> Hz, in <s> s" (model::scene::body).
    let note = slave
        .logs()
        .into_iter()
        .find(|l| l.contains(" modes, ") && l.contains(" Hz, in "))
        .ok_or_else(|| failed("the reduced body's log note"))?;
    let words: Vec<&str> = note.split_whitespace().collect();
    let after = |key: &str| -> f64 {
        words
            .iter()
            .position(|w| *w == key)
            .and_then(|k| words.get(k + 1))
            .and_then(|w| w.trim_end_matches(',').parse().ok())
            .unwrap_or(f64::NAN)
    };
    let before = |key: &str| -> String {
        words
            .iter()
            .position(|w| w.starts_with(key))
            .and_then(|k| k.checked_sub(1))
            .map_or_else(|| "?".into(), |k| words[k].trim_end_matches(',').to_owned())
    };
    let (n_modes, range_hz, t_reduce) = (before("modes,"), before("Hz,"), after("in"));
    let (status, frequencies) = slave.get_real(&real::MODE_FREQUENCY[..1]);
    ok(status, "mode[1].frequency")?;

    let t0 = Instant::now();
    let h = 1e-3;
    let forces: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    let mut largest_force = 0.0_f64;
    for k in 0..100 {
        ok(slave.do_step(k as f64 * h, h), "fmi2DoStep")?;
        let (status, f) = slave.get_real(&forces);
        ok(status, "mount.F")?;
        if f.iter().any(|v| !v.is_finite()) {
            return Err(failed("finite mount forces").into());
        }
        largest_force = f.iter().fold(largest_force, |m, v| m.max(v.abs()));
    }
    let t_sim = t0.elapsed().as_secs_f64();
    let (status, steps) = slave.get_integer(&[integer::SOLVER_STEPS]);
    ok(status, "solver.steps")?;
    ok(slave.terminate(), "fmi2Terminate")?;
    drop(slave);
    println!(
        "result nodes={n_nodes} bushes={n_bushes} read_s={t_read:.2} hwm_read_mb={hwm_read:.0} \
         fmu_init_s={t_init:.2} read_cpu_s={c_read:.2} fmu_init_cpu_s={c_init:.2} \
         reduce_s={t_reduce:.2} modes={n_modes} range_hz={range_hz} mode1_hz={:.3} \
         sim_s={t_sim:.2} steps={} largest_force_n={largest_force:.1} hwm_mb={:.0} load={}",
        frequencies[0],
        steps[0],
        vm_hwm_mb(),
        load().replace(' ', "/")
    );
    Ok(())
}

fn text_field(line: &str, key: &str) -> String {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(&format!("{key}=")))
        .unwrap_or("?")
        .to_owned()
}

fn field(line: &str, key: &str) -> f64 {
    text_field(line, key).parse().unwrap_or(f64::NAN)
}

fn child(args: &[String]) -> Res<String> {
    let exe = std::env::current_exe()?;
    let out = Command::new(exe).args(args).output()?;
    if !out.status.success() {
        return Err(format!(
            "child {args:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        )
        .into());
    }
    Ok(String::from_utf8(out.stdout)?)
}

/// Least-squares slope of log y against log x.
fn exponent(x: &[f64], y: &[f64]) -> f64 {
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

fn sizes_table(refinements: &[usize], extra_modes: usize) -> Res<()> {
    let root = std::env::temp_dir().join(format!("production-benchmark-{}", std::process::id()));
    println!("| refinement | nodes | DOF (6/node) | deck MB | write (s) | read (s) | FMU initialisation (s) | of which reduction (s) | initialisation CPU (s) | reduced modes | their range (Hz) | 100 doSteps of 1 ms (s) | peak memory (GB) | load |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    let mut rows: Vec<(f64, f64, f64, f64)> = Vec::new();
    let mut last_dir = PathBuf::new();
    for &r in refinements {
        let dir = root.join(format!("r{r}"));
        let written = child(&["write".into(), r.to_string(), dir.display().to_string()])?;
        std::fs::write(dir.join("points.txt"), &written)?;
        let summary = written
            .lines()
            .find(|l| l.starts_with("written"))
            .unwrap_or("")
            .to_owned();
        let w: Vec<&str> = summary.split_whitespace().collect();
        let result = child(&[
            "run".into(),
            r.to_string(),
            dir.display().to_string(),
            "0".into(),
            "0".into(),
        ])?;
        let line = result
            .lines()
            .find(|l| l.starts_with("result"))
            .unwrap_or("")
            .to_owned();
        let nodes = field(&line, "nodes");
        let dof = 6.0 * nodes;
        let read = field(&line, "read_s");
        let init_cpu = field(&line, "fmu_init_cpu_s");
        let hwm = field(&line, "hwm_mb") / 1024.0;
        println!(
            "| {r} | {nodes:.0} | {dof:.0} | {} | {} | {read:.2} | {:.1} | {:.1} | {init_cpu:.1} | {} | {} | {:.3} | {hwm:.2} | {} |",
            w.get(7).unwrap_or(&"?"),
            w.get(9).unwrap_or(&"?"),
            field(&line, "fmu_init_s"),
            field(&line, "reduce_s"),
            text_field(&line, "modes"),
            text_field(&line, "range_hz"),
            field(&line, "sim_s"),
            text_field(&line, "load")
        );
        eprintln!("{summary}\n{line}");
        rows.push((dof, read, init_cpu, hwm));
        last_dir = dir;
    }
    if rows.len() >= 2 {
        let x: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let fit = |f: fn(&(f64, f64, f64, f64)) -> f64| {
            exponent(&x, &rows.iter().map(f).collect::<Vec<_>>())
        };
        println!(
            "\ngrowth exponents against DOF (log-log least squares): read time {:.2}, FMU \
             initialisation CPU time {:.2}, peak memory {:.2}",
            fit(|r| r.1),
            fit(|r| r.2),
            fit(|r| r.3)
        );
    }
    if extra_modes > 0 {
        let result = child(&[
            "run".into(),
            "0".into(),
            last_dir.display().to_string(),
            "0".into(),
            extra_modes.to_string(),
        ])?;
        let line = result
            .lines()
            .find(|l| l.starts_with("result"))
            .unwrap_or("")
            .to_owned();
        eprintln!("{line}");
        println!(
            "\nlargest deck, {extra_modes} fixed-interface modes: read {:.2} s, FMU \
             initialisation {:.1} s ({:.1} s CPU) of which reduction {:.1} s, {} reduced modes \
             ({} Hz), 100 doSteps of 1 ms {:.3} s, peak memory {:.2} GB, load {}",
            field(&line, "read_s"),
            field(&line, "fmu_init_s"),
            field(&line, "fmu_init_cpu_s"),
            field(&line, "reduce_s"),
            text_field(&line, "modes"),
            text_field(&line, "range_hz"),
            field(&line, "sim_s"),
            field(&line, "hwm_mb") / 1024.0,
            text_field(&line, "load")
        );
    }
    let _ = std::fs::remove_dir_all(&root);
    Ok(())
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("modes") => modes_table(),
        Some("write") => write_deck(args[1].parse()?, Path::new(&args[2])),
        Some("run") => run_deck(Path::new(&args[2]), args[3].parse()?, args[4].parse()?),
        Some("sizes") => {
            let mut refinements = Vec::new();
            let mut modes = 0;
            let mut it = args[1..].iter();
            while let Some(a) = it.next() {
                if a == "--modes" {
                    modes = it.next().ok_or("--modes needs a number")?.parse()?;
                } else {
                    refinements.push(a.parse()?);
                }
            }
            if refinements.is_empty() {
                refinements = vec![1, 2, 4, 8];
            }
            sizes_table(&refinements, modes)
        }
        _ => Err("usage: production_benchmark modes | sizes [r…] [--modes N]".into()),
    }
}
