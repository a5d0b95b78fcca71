//! Complete integrator state for `fmi2GetFMUstate` / `fmi2SetFMUstate`, and its serialisation
//! for `fmi2SerializeFMUstate` in the crate's one saved-state format ([`crate::saved_state`]).

use serde::{Deserialize, Serialize};

use super::bdf::{Bdf, BdfState};
use super::error::BdfError;
use crate::saved_state;

/// Identifies a serialised BDF snapshot.
const MAGIC: &[u8; 8] = b"EMC-BDF\0";
/// Layout version of the serialisation (4: postcard; 1–3 were hand-written `f64` layouts).
const VERSION: u32 = 4;
/// Larger systems are refused on loading (the dense iteration matrix alone would need 2^51 bytes).
const MAX_STATES: usize = 1 << 24;

/// Everything needed to continue an integration bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BdfState", into = "BdfState")]
pub struct BdfSnapshot {
    pub(super) state: BdfState,
}

impl Bdf {
    /// Captures the complete integrator state.
    pub fn snapshot(&self) -> BdfSnapshot {
        BdfSnapshot {
            state: self.s.clone(),
        }
    }

    /// Returns to a captured state. The snapshot must come from an integrator of the same
    /// problem dimension.
    pub fn restore(&mut self, snapshot: &BdfSnapshot) -> Result<(), BdfError> {
        if snapshot.state.n != self.s.n {
            return Err(BdfError::BadSnapshot(format!(
                "snapshot has {} states, this integrator {}",
                snapshot.state.n, self.s.n
            )));
        }
        if !snapshot.state.lin.matrix.same_structure(&self.s.lin.matrix) {
            return Err(BdfError::BadSnapshot(
                "the snapshot's Jacobian structure differs from this problem's".to_string(),
            ));
        }
        self.s = snapshot.state.clone();
        Ok(())
    }
}

impl BdfSnapshot {
    /// Time of the captured state.
    pub fn t(&self) -> f64 {
        self.state.tn
    }

    /// The snapshot as bytes (magic, version, postcard body).
    pub fn to_bytes(&self) -> Vec<u8> {
        saved_state::encode(MAGIC, VERSION, &self.state)
    }

    /// Parses [`Self::to_bytes`] output, checking magic, version and consistency.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, BdfError> {
        let state: BdfState = saved_state::decode(bytes, MAGIC, VERSION, "a BDF snapshot")
            .map_err(BdfError::BadSnapshot)?;
        Self::try_from(state).map_err(BdfError::BadSnapshot)
    }
}

impl From<BdfSnapshot> for BdfState {
    fn from(snapshot: BdfSnapshot) -> Self {
        snapshot.state
    }
}

impl TryFrom<BdfState> for BdfSnapshot {
    type Error = String;

    /// Accepts a decoded state only when its parts fit together, so that continuing from it
    /// cannot index out of bounds.
    fn try_from(s: BdfState) -> Result<Self, String> {
        let n = s.n;
        if n == 0 || n > MAX_STATES {
            return Err(format!("implausible number of states {n}"));
        }
        s.opts.validate(n).map_err(|e| e.to_string())?;
        let max_order = s.opts.max_order;
        if s.zn.zn.len() != max_order + 1 {
            return Err(format!(
                "history has {} columns for max_order {max_order}",
                s.zn.zn.len()
            ));
        }
        if s.zn.zn.iter().any(|col| col.len() != n) || s.acor.len() != n {
            return Err(format!("history vectors of a length other than {n}"));
        }
        if !(1..=max_order).contains(&s.q) || !(1..=max_order).contains(&s.qprime) {
            return Err(format!(
                "order {} (next {}) outside 1..={max_order}",
                s.q, s.qprime
            ));
        }
        let scalars = [
            ("tn", s.tn),
            ("h", s.h),
            ("hprime", s.hprime),
            ("hscale", s.hscale),
            ("eta", s.eta),
            ("etamax", s.etamax),
            ("hu", s.hu),
            ("rl1", s.rl1),
            ("gamma", s.gamma),
            ("gammap", s.gammap),
            ("gamrat", s.gamrat),
            ("crate", s.crate_),
            ("delp", s.delp),
            ("acnrm", s.acnrm),
            ("saved_tq5", s.saved_tq5),
        ];
        if let Some((name, x)) = scalars.iter().find(|(_, x)| !x.is_finite()) {
            return Err(format!("{name} = {x} is not finite"));
        }
        let coefficients = s.tau.iter().chain(&s.tq).chain(&s.l);
        if coefficients.chain(&s.acor).any(|x| !x.is_finite()) {
            return Err("a method coefficient or correction is not finite".into());
        }
        if let Some(k) =
            s.zn.zn
                .iter()
                .position(|col| col.iter().any(|x| !x.is_finite()))
        {
            return Err(format!("history column {k} holds a non-finite value"));
        }
        if s.tstop.is_nan() || s.h_unclipped.is_some_and(|h| !h.is_finite()) {
            return Err("the stop time or the unclipped step is not a number".into());
        }
        if s.lin.matrix.dim() != n {
            return Err(format!(
                "an iteration matrix of {} states for {n}",
                s.lin.matrix.dim()
            ));
        }
        Ok(Self { state: s })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::test_problems::SpringChain;
    use crate::ode::BdfOptions;

    /// Issue 28: NaN in the integrator's history passed a saved state's checks.
    #[test]
    fn a_non_finite_history_or_time_is_refused() {
        let good = advanced_snapshot();
        let mut history = good.state.clone();
        history.zn.zn[2][7] = f64::NAN;
        let e = BdfSnapshot::try_from(history).unwrap_err();
        assert!(e.contains("history column 2"), "{e}");
        let mut time = good.state.clone();
        time.tn = f64::INFINITY;
        let e = BdfSnapshot::try_from(time).unwrap_err();
        assert!(e.contains("tn = inf"), "{e}");
    }

    fn advanced_snapshot() -> BdfSnapshot {
        let mut p = SpringChain::standard(false).expect("standard chain");
        let mut bdf = Bdf::new(&mut p, 0.0, &[0.0; 40], BdfOptions::default()).unwrap();
        bdf.advance_to(&mut p, 0.01).unwrap();
        bdf.snapshot()
    }

    #[test]
    fn a_forged_dimension_is_refused() {
        let mut snap = advanced_snapshot();
        snap.state.n = 1 << 23;
        let bytes = saved_state::encode(MAGIC, VERSION, &snap.state);
        assert!(matches!(
            BdfSnapshot::from_bytes(&bytes),
            Err(BdfError::BadSnapshot(_))
        ));
        let mut snap = advanced_snapshot();
        snap.state.acor.pop();
        let bytes = saved_state::encode(MAGIC, VERSION, &snap.state);
        assert!(BdfSnapshot::from_bytes(&bytes).is_err());
    }

    #[test]
    fn every_truncation_and_byte_flip_is_handled_without_panic() {
        let bytes = advanced_snapshot().to_bytes();
        for cut in 0..bytes.len() {
            assert!(BdfSnapshot::from_bytes(&bytes[..cut]).is_err(), "cut {cut}");
        }
        // A flipped byte either still decodes to a consistent state or is refused; never a panic.
        for at in (0..bytes.len()).step_by(7) {
            let mut damaged = bytes.clone();
            damaged[at] ^= 0x5a;
            let _ = BdfSnapshot::from_bytes(&damaged);
        }
    }
}
