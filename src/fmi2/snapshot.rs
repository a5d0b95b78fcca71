//! The serialized FMU state: a versioned, length-checked byte layout of [`Core`].
//!
//! Layout (little endian): magic, format version, GUID, phase, times, the variable values, the
//! input signals, and the simulation's dynamic state. The model itself is not stored: it is
//! rebuilt from the stored parameters, so a buffer stays small and cannot smuggle in a model.

use super::input_track::InputTrack;
use super::instance::{Core, Values};
use super::state::Phase;
use super::variables::{BOOLEANS, GUID, INTEGERS, REALS, STRINGS};
use crate::cosim::Simulation;

const MAGIC: &[u8; 8] = b"EMCSTATE";
const FORMAT_VERSION: u32 = 2;

/// Serializes a state captured by `fmi2GetFMUstate`.
pub fn serialize(core: &Core) -> Vec<u8> {
    let mut w = Writer(Vec::with_capacity(4096));
    w.bytes(MAGIC);
    w.u32(FORMAT_VERSION);
    w.str(GUID);
    w.u8(core.phase.code());
    w.f64(core.start_time);
    w.u8(u8::from(core.stop_time.is_some()));
    w.f64(core.stop_time.unwrap_or(0.0));
    w.f64(core.time);
    w.u8(u8::from(core.terminated));
    w.optional(core.experiment_tolerance);
    w.u32(core.explicit.len() as u32);
    core.explicit.iter().for_each(|name| w.str(name));
    w.u32(core.values.reals.len() as u32);
    core.values.reals.iter().for_each(|x| w.f64(*x));
    w.u32(core.values.integers.len() as u32);
    core.values.integers.iter().for_each(|x| w.u32(*x as u32));
    w.u32(core.values.booleans.len() as u32);
    core.values.booleans.iter().for_each(|x| w.u8(u8::from(*x)));
    w.u32(core.values.strings.len() as u32);
    core.values.strings.iter().for_each(|x| w.str(x));
    w.u32(core.inputs.len() as u32);
    core.inputs.iter().for_each(|track| w.track(track));
    match &core.simulation {
        Some(sim) => {
            let dynamic = sim.dynamic_state();
            w.u8(1);
            w.u32(dynamic.len() as u32);
            dynamic.iter().for_each(|x| w.f64(*x));
        }
        None => w.u8(0),
    }
    w.0
}

/// Rebuilds a state from bytes; `rebuild` constructs the simulation from the stored values and
/// the simulation's dynamic state.
pub fn deserialize(
    bytes: &[u8],
    rebuild: impl FnOnce(&Core, &[f64]) -> Result<Simulation, String>,
) -> Result<Core, String> {
    let mut r = Reader {
        data: bytes,
        pos: 0,
    };
    if r.take(MAGIC.len())? != MAGIC {
        return Err("not an FMU state of this model (bad magic)".into());
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "FMU state format version {version}, expected {FORMAT_VERSION}"
        ));
    }
    let guid = r.str()?;
    if guid != GUID {
        return Err(format!(
            "FMU state belongs to GUID {guid}, this FMU is {GUID}"
        ));
    }
    let phase = Phase::from_code(r.u8()?).ok_or("unknown phase code")?;
    let start_time = r.f64()?;
    let has_stop = r.u8()? != 0;
    let stop = r.f64()?;
    let time = r.f64()?;
    let terminated = r.u8()? != 0;
    let experiment_tolerance = r.optional()?;
    let explicit_count = r.u32()? as usize;
    if explicit_count > REALS.len() + INTEGERS.len() + BOOLEANS.len() + STRINGS.len() {
        return Err(format!(
            "FMU state names {explicit_count} explicitly set parameters"
        ));
    }
    let explicit = (0..explicit_count)
        .map(|_| r.str())
        .collect::<Result<std::collections::BTreeSet<_>, _>>()?;
    let reals = r.counted(REALS.len(), "Real values", |r| r.f64())?;
    let integers = r.counted(INTEGERS.len(), "Integer values", |r| {
        r.u32().map(|x| x as i32)
    })?;
    let booleans = r.counted(BOOLEANS.len(), "Boolean values", |r| r.u8().map(|x| x != 0))?;
    let strings = r.counted(STRINGS.len(), "String values", |r| r.str())?;
    let inputs = r.counted(REALS.len(), "input signals", |r| r.track())?;
    let has_simulation = r.u8()? != 0;
    let dynamic = if has_simulation {
        let n = r.u32()? as usize;
        if n > r.remaining() / 8 {
            return Err("truncated simulation state".into());
        }
        (0..n).map(|_| r.f64()).collect::<Result<Vec<_>, _>>()?
    } else {
        Vec::new()
    };
    if r.remaining() != 0 {
        return Err(format!(
            "{} trailing bytes after the FMU state",
            r.remaining()
        ));
    }
    let mut core = Core {
        phase,
        values: Values {
            reals,
            integers,
            booleans,
            strings,
        },
        inputs,
        start_time,
        stop_time: has_stop.then_some(stop),
        experiment_tolerance,
        explicit,
        time,
        terminated,
        simulation: None,
    };
    super::instance::check_values(&core.values, &core.inputs)?;
    if has_simulation {
        core.simulation = Some(rebuild(&core, &dynamic)?);
    }
    Ok(core)
}

struct Writer(Vec<u8>);

impl Writer {
    fn bytes(&mut self, b: &[u8]) {
        self.0.extend_from_slice(b);
    }
    fn u8(&mut self, x: u8) {
        self.0.push(x);
    }
    fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }
    fn f64(&mut self, x: f64) {
        self.bytes(&x.to_le_bytes());
    }
    fn str(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.bytes(s.as_bytes());
    }
    fn optional(&mut self, x: Option<f64>) {
        self.u8(u8::from(x.is_some()));
        self.f64(x.unwrap_or(0.0));
    }
    fn track(&mut self, t: &InputTrack) {
        self.f64(t.value);
        self.f64(t.slope);
        self.f64(t.since);
        self.optional(t.pending_value);
        self.optional(t.pending_slope);
        self.optional(t.last_set.map(|(time, _)| time));
        self.f64(t.last_set.map_or(0.0, |(_, value)| value));
        self.optional(t.last_slope);
    }
}

struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if n > self.remaining() {
            return Err(format!(
                "truncated FMU state: needs {n} more bytes at offset {}",
                self.pos
            ));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn f64(&mut self) -> Result<f64, String> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }
    fn str(&mut self) -> Result<String, String> {
        let n = self.u32()? as usize;
        let b = self.take(n)?;
        String::from_utf8(b.to_vec()).map_err(|_| "string in FMU state is not UTF-8".to_owned())
    }
    fn optional(&mut self) -> Result<Option<f64>, String> {
        let present = self.u8()? != 0;
        let x = self.f64()?;
        Ok(present.then_some(x))
    }
    fn track(&mut self) -> Result<InputTrack, String> {
        let value = self.f64()?;
        let slope = self.f64()?;
        let since = self.f64()?;
        let pending_value = self.optional()?;
        let pending_slope = self.optional()?;
        let last_time = self.optional()?;
        let last_value = self.f64()?;
        let last_slope = self.optional()?;
        Ok(InputTrack {
            value,
            slope,
            since,
            pending_value,
            pending_slope,
            last_set: last_time.map(|t| (t, last_value)),
            last_slope,
        })
    }
    fn counted<T>(
        &mut self,
        expected: usize,
        what: &str,
        mut item: impl FnMut(&mut Self) -> Result<T, String>,
    ) -> Result<Vec<T>, String> {
        let n = self.u32()? as usize;
        if n != expected {
            return Err(format!("FMU state has {n} {what}, this FMU has {expected}"));
        }
        (0..n).map(|_| item(self)).collect()
    }
}
