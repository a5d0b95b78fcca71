//! Complete integrator state for `fmi2GetFMUstate` / `fmi2SetFMUstate`, and its flat, versioned
//! `f64` serialisation for `fmi2SerializeFMUstate`.

use faer::Mat;

use super::bdf::{Bdf, BdfState, LinearSystem};
use super::block_low_rank::{BlockLowRankJacobian, BlockLowRankLu, BlockLowRankShape};
use super::coefficients::L_MAX;
use super::error::BdfError;
use super::linear_solver::{DenseLu, IterationMatrix};
use super::nordsieck::Nordsieck;
use super::options::{BdfOptions, Tolerance};
use super::stability::StabilityGuard;
use super::stats::BdfStats;

/// Identifies a serialised BDF snapshot.
const MAGIC: f64 = 4_262_000_917.0;
/// Layout version of the serialisation.
const VERSION: f64 = 3.0;

/// Everything needed to continue an integration bit for bit.
#[derive(Debug, Clone, PartialEq)]
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

    /// Flat serialisation: magic, version, length, then the fields in a fixed order.
    pub fn to_f64_vec(&self) -> Vec<f64> {
        let s = &self.state;
        let mut w = Writer(vec![MAGIC, VERSION, 0.0]);
        w.usize(s.n);
        w.usize(s.zn.zn.len());
        // Options.
        let o = &s.opts;
        w.f(o.rtol);
        match &o.atol {
            Tolerance::Scalar(a) => {
                w.f(0.0);
                w.f(*a);
            }
            Tolerance::Vector(v) => {
                w.f(1.0);
                w.slice(v);
            }
        }
        w.usize(o.max_order);
        match o.h_init {
            Some(h) => {
                w.f(1.0);
                w.f(h);
            }
            None => {
                w.f(0.0);
                w.f(0.0);
            }
        }
        w.f(o.h_min);
        w.f(o.h_max);
        w.usize(o.max_steps_per_call);
        w.usize(o.max_err_test_fails);
        w.usize(o.max_conv_fails);
        w.bool(o.stability_limit_detection);
        match &o.magnitude_cap {
            Some(cap) => {
                w.f(1.0);
                w.slice(cap);
            }
            None => w.f(0.0),
        }
        // Step state.
        for v in [s.tn, s.h, s.hprime, s.hscale, s.eta, s.etamax, s.hu] {
            w.f(v);
        }
        w.usize(s.q);
        w.usize(s.qprime);
        w.usize(s.qwait);
        w.slice(&s.tau);
        w.slice(&s.tq);
        w.slice(&s.l);
        for v in [
            s.rl1,
            s.gamma,
            s.gammap,
            s.gamrat,
            s.crate_,
            s.delp,
            s.acnrm,
            s.saved_tq5,
        ] {
            w.f(v);
        }
        w.u64(s.nst);
        w.u64(s.nstlp);
        w.u64(s.nscon);
        for col in &s.zn.zn {
            w.slice(col);
        }
        w.slice(&s.acor);
        // Linear system.
        match &s.lin.matrix {
            IterationMatrix::Dense { saved_j, lu } => {
                w.f(0.0);
                w.mat(saved_j);
                let (lu, perm, perm_inv, factored) = lu.parts();
                w.mat(lu);
                for &p in perm.iter().chain(perm_inv) {
                    w.usize(p);
                }
                w.bool(factored);
            }
            IterationMatrix::BlockLowRank { saved_j, lu } => {
                // The factorisation is a deterministic function of J and gammap: it is rebuilt.
                w.f(1.0);
                let shape = saved_j.shape();
                w.usize(shape.blocks.len());
                for b in &shape.blocks {
                    w.usize(b.len());
                    for &i in b {
                        w.usize(i);
                    }
                }
                w.usize(shape.rank);
                let (values, u, v) = saved_j.values();
                w.slice(values);
                w.cols(u);
                w.cols(v);
                w.bool(lu.is_factored());
            }
        }
        w.u64(s.lin.nstlj);
        w.bool(s.lin.jcur);
        // Counters.
        let st = &s.stats;
        for v in [
            st.steps,
            st.rhs_evals,
            st.rhs_evals_jac,
            st.jac_evals,
            st.factorizations,
            st.newton_iters,
            st.err_test_fails,
            st.conv_fails,
            st.stability_order_reductions,
        ] {
            w.u64(v);
        }
        w.usize(st.order);
        w.f(st.h);
        w.f(st.h_next);
        w.usize(st.order_next);
        // Driver and stability guard.
        w.bool(s.pending_h0);
        w.f(s.tstop);
        match s.h_unclipped {
            Some(h) => {
                w.f(1.0);
                w.f(h);
            }
            None => {
                w.f(0.0);
                w.f(0.0);
            }
        }
        let g = &s.stability;
        w.usize(g.failures.len());
        for &(n, h, t) in &g.failures {
            w.u64(n);
            w.f(h);
            w.f(t);
        }
        w.u64(g.hold_until);
        w.u64(g.hold_len);
        match g.last_release {
            Some(r) => {
                w.f(1.0);
                w.u64(r);
            }
            None => {
                w.f(0.0);
                w.f(0.0);
            }
        }
        w.u64(g.triggers);
        w.f(g.h_trigger);
        w.u64(g.hold_start);
        w.f(g.t_hold_start);
        w.f(g.t_release);
        w.u64(g.lockout_until);
        w.u64(g.lockout_len);
        w.bool(s.fixed);
        let len = w.0.len();
        w.0[2] = len as f64;
        w.0
    }

    /// Parses [`Self::to_f64_vec`] output, checking magic, version, length and consistency.
    pub fn from_f64_slice(data: &[f64]) -> Result<Self, BdfError> {
        let bad = |m: String| BdfError::BadSnapshot(m);
        if data.len() < 5 {
            return Err(bad(format!(
                "{} values is too short for a BDF snapshot",
                data.len()
            )));
        }
        if data[0] != MAGIC {
            return Err(bad("not a BDF snapshot (wrong magic number)".to_string()));
        }
        if data[1] != VERSION {
            return Err(bad(format!(
                "version {} is not supported (expected {VERSION})",
                data[1]
            )));
        }
        if data[2] != data.len() as f64 {
            return Err(bad(format!(
                "declared length {} but {} values were given",
                data[2],
                data.len()
            )));
        }
        let mut r = Reader { data, pos: 3 };
        let n = r.usize("n")?;
        let ncols = r.usize("history length")?;
        if n == 0 || n > 1 << 24 || !(2..=6).contains(&ncols) {
            return Err(bad(format!(
                "implausible sizes n = {n}, history columns = {ncols}"
            )));
        }
        let rtol = r.f()?;
        let atol = match r.f()? {
            0.0 => Tolerance::Scalar(r.f()?),
            1.0 => Tolerance::Vector(r.vec(n)?),
            t => return Err(bad(format!("unknown tolerance tag {t}"))),
        };
        let max_order = r.usize("max_order")?;
        let h_init = match (r.f()?, r.f()?) {
            (1.0, h) => Some(h),
            _ => None,
        };
        let opts = BdfOptions {
            rtol,
            atol,
            max_order,
            h_init,
            h_min: r.f()?,
            h_max: r.f()?,
            max_steps_per_call: r.usize("max_steps_per_call")?,
            max_err_test_fails: r.usize("max_err_test_fails")?,
            max_conv_fails: r.usize("max_conv_fails")?,
            stability_limit_detection: r.bool()?,
            magnitude_cap: match r.f()? {
                0.0 => None,
                1.0 => Some(r.vec(n)?),
                t => return Err(bad(format!("unknown magnitude-cap tag {t}"))),
            },
        };
        opts.validate(n)?;
        if ncols != max_order + 1 {
            return Err(bad(format!(
                "history has {ncols} columns for max_order {max_order}"
            )));
        }
        let (tn, h, hprime, hscale, eta, etamax, hu) =
            (r.f()?, r.f()?, r.f()?, r.f()?, r.f()?, r.f()?, r.f()?);
        let q = r.usize("q")?;
        let qprime = r.usize("qprime")?;
        let qwait = r.usize("qwait")?;
        if !(1..=max_order).contains(&q) || !(1..=max_order).contains(&qprime) {
            return Err(bad(format!(
                "order {q} (next {qprime}) outside 1..={max_order}"
            )));
        }
        let tau = r.array::<{ L_MAX + 1 }>()?;
        let tq = r.array::<6>()?;
        let l = r.array::<{ L_MAX + 1 }>()?;
        let (rl1, gamma, gammap, gamrat, crate_, delp, acnrm, saved_tq5) = (
            r.f()?,
            r.f()?,
            r.f()?,
            r.f()?,
            r.f()?,
            r.f()?,
            r.f()?,
            r.f()?,
        );
        let (nst, nstlp, nscon) = (r.u64()?, r.u64()?, r.u64()?);
        let mut zn = Nordsieck::new(n, max_order);
        for col in zn.zn.iter_mut() {
            *col = r.vec(n)?;
        }
        let acor = r.vec(n)?;
        let matrix = match r.f()? {
            0.0 => {
                // The two n x n matrices alone need 2 n^2 values: refuse before allocating.
                if n.checked_mul(n)
                    .and_then(|nn| nn.checked_mul(2))
                    .is_none_or(|need| need > data.len() - r.pos)
                {
                    return Err(bad(format!(
                        "{} values cannot hold the dense Jacobian of {n} states",
                        data.len()
                    )));
                }
                let saved_j = r.mat(n)?;
                let lu = r.mat(n)?;
                let mut perm = Vec::with_capacity(n);
                for _ in 0..n {
                    perm.push(r.usize("permutation")?);
                }
                let mut perm_inv = Vec::with_capacity(n);
                for _ in 0..n {
                    perm_inv.push(r.usize("permutation")?);
                }
                if (0..n).any(|i| perm[i] >= n || perm_inv[i] >= n || perm_inv[perm[i]] != i) {
                    return Err(bad(
                        "the LU row permutation is not a permutation".to_string()
                    ));
                }
                let factored = r.bool()?;
                IterationMatrix::Dense {
                    saved_j,
                    lu: DenseLu::from_parts(lu, perm, perm_inv, factored),
                }
            }
            1.0 => {
                let nblocks = r.usize("block count")?;
                if nblocks > n {
                    return Err(bad(format!("{nblocks} blocks for {n} states")));
                }
                let mut blocks = Vec::with_capacity(nblocks);
                let mut entries = 0usize;
                for _ in 0..nblocks {
                    let len = r.usize("block size")?;
                    if len > n {
                        return Err(bad(format!("a block of {len} states in a system of {n}")));
                    }
                    let mut b = Vec::with_capacity(len);
                    for _ in 0..len {
                        b.push(r.usize("block index")?);
                    }
                    entries += len * len;
                    blocks.push(b);
                }
                let rank = r.usize("rank")?;
                let shape = BlockLowRankShape { blocks, rank };
                shape.validate(n).map_err(bad)?;
                if entries + 2 * n * rank > data.len() - r.pos {
                    return Err(bad(format!(
                        "{} values cannot hold a rank-{rank} Jacobian of {n} states",
                        data.len()
                    )));
                }
                let values = r.vec(entries)?;
                let u = r.cols(n, rank)?;
                let v = r.cols(n, rank)?;
                let factored = r.bool()?;
                let saved_j = BlockLowRankJacobian::from_values(shape, values, u, v)
                    .ok_or_else(|| bad("Jacobian sizes do not match its shape".to_string()))?;
                let mut lu = BlockLowRankLu::new(saved_j.shape());
                if factored && !lu.factor(&saved_j, gammap) {
                    return Err(bad("the saved iteration matrix is singular".to_string()));
                }
                IterationMatrix::BlockLowRank {
                    saved_j: Box::new(saved_j),
                    lu: Box::new(lu),
                }
            }
            t => return Err(bad(format!("unknown linear-system tag {t}"))),
        };
        let nstlj = r.u64()?;
        let jcur = r.bool()?;
        let mut counters = [0u64; 9];
        for c in counters.iter_mut() {
            *c = r.u64()?;
        }
        let stats = BdfStats {
            steps: counters[0],
            rhs_evals: counters[1],
            rhs_evals_jac: counters[2],
            jac_evals: counters[3],
            factorizations: counters[4],
            newton_iters: counters[5],
            err_test_fails: counters[6],
            conv_fails: counters[7],
            stability_order_reductions: counters[8],
            order: r.usize("order")?,
            h: r.f()?,
            h_next: r.f()?,
            order_next: r.usize("order_next")?,
        };
        let pending_h0 = r.bool()?;
        let tstop = r.f()?;
        let h_unclipped = match (r.f()?, r.f()?) {
            (1.0, h) => Some(h),
            _ => None,
        };
        let nfail = r.usize("stability failures")?;
        if nfail > 1000 {
            return Err(bad(format!("implausible stability record length {nfail}")));
        }
        let mut failures = Vec::with_capacity(nfail);
        for _ in 0..nfail {
            failures.push((r.u64()?, r.f()?, r.f()?));
        }
        let hold_until = r.u64()?;
        let hold_len = r.u64()?;
        let last_release = match r.f()? {
            1.0 => Some(r.u64()?),
            _ => {
                r.f()?;
                None
            }
        };
        let triggers = r.u64()?;
        let h_trigger = r.f()?;
        let hold_start = r.u64()?;
        let t_hold_start = r.f()?;
        let t_release = r.f()?;
        let lockout_until = r.u64()?;
        let lockout_len = r.u64()?;
        let fixed = r.bool()?;
        if r.pos != data.len() {
            return Err(bad(format!("{} trailing values", data.len() - r.pos)));
        }
        let state = BdfState {
            opts,
            n,
            tn,
            h,
            hprime,
            hscale,
            eta,
            etamax,
            hu,
            q,
            qprime,
            qwait,
            tau,
            tq,
            l,
            rl1,
            gamma,
            gammap,
            gamrat,
            crate_,
            delp,
            acnrm,
            saved_tq5,
            nst,
            nstlp,
            nscon,
            zn,
            acor,
            lin: LinearSystem {
                matrix,
                nstlj,
                jcur,
            },
            stats,
            pending_h0,
            tstop,
            h_unclipped,
            stability: StabilityGuard {
                failures,
                hold_until,
                hold_len,
                last_release,
                triggers,
                h_trigger,
                hold_start,
                t_hold_start,
                t_release,
                lockout_until,
                lockout_len,
            },
            fixed,
        };
        Ok(Self { state })
    }

    /// Serialisation as little-endian bytes of [`Self::to_f64_vec`].
    pub fn to_bytes(&self) -> Vec<u8> {
        self.to_f64_vec()
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect()
    }

    /// Inverse of [`Self::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, BdfError> {
        if bytes.len() % 8 != 0 {
            return Err(BdfError::BadSnapshot(format!(
                "{} bytes is not a whole number of f64 values",
                bytes.len()
            )));
        }
        let data: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
            .collect();
        Self::from_f64_slice(&data)
    }
}

struct Writer(Vec<f64>);

impl Writer {
    fn f(&mut self, v: f64) {
        self.0.push(v);
    }
    fn usize(&mut self, v: usize) {
        self.0.push(v as f64);
    }
    fn u64(&mut self, v: u64) {
        self.0.push(v as f64);
    }
    fn bool(&mut self, v: bool) {
        self.0.push(if v { 1.0 } else { 0.0 });
    }
    fn slice(&mut self, v: &[f64]) {
        self.0.extend_from_slice(v);
    }
    fn mat(&mut self, m: &Mat<f64>) {
        self.cols(m);
    }
    fn cols(&mut self, m: &Mat<f64>) {
        for j in 0..m.ncols() {
            self.0.extend_from_slice(m.col_as_slice(j));
        }
    }
}

struct Reader<'a> {
    data: &'a [f64],
    pos: usize,
}

impl Reader<'_> {
    fn f(&mut self) -> Result<f64, BdfError> {
        let v = *self
            .data
            .get(self.pos)
            .ok_or_else(|| BdfError::BadSnapshot(format!("truncated at value {}", self.pos)))?;
        self.pos += 1;
        Ok(v)
    }
    fn u64(&mut self) -> Result<u64, BdfError> {
        let v = self.f()?;
        if v >= 0.0 && v.fract() == 0.0 && v < 9.0e15 {
            Ok(v as u64)
        } else {
            Err(BdfError::BadSnapshot(format!(
                "value {v} at {} is not a count",
                self.pos - 1
            )))
        }
    }
    fn usize(&mut self, what: &str) -> Result<usize, BdfError> {
        let v = self.u64().map_err(|_| {
            BdfError::BadSnapshot(format!("`{what}` is not a non-negative integer"))
        })?;
        usize::try_from(v)
            .map_err(|_| BdfError::BadSnapshot(format!("`{what}` = {v} is too large")))
    }
    fn bool(&mut self) -> Result<bool, BdfError> {
        match self.f()? {
            0.0 => Ok(false),
            1.0 => Ok(true),
            v => Err(BdfError::BadSnapshot(format!(
                "flag value {v} at {} is not 0 or 1",
                self.pos - 1
            ))),
        }
    }
    fn vec(&mut self, n: usize) -> Result<Vec<f64>, BdfError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        let end =
            end.ok_or_else(|| BdfError::BadSnapshot(format!("truncated at value {}", self.pos)))?;
        let v = self.data[self.pos..end].to_vec();
        self.pos = end;
        Ok(v)
    }
    fn array<const K: usize>(&mut self) -> Result<[f64; K], BdfError> {
        let mut a = [0.0; K];
        for x in a.iter_mut() {
            *x = self.f()?;
        }
        Ok(a)
    }
    fn mat(&mut self, n: usize) -> Result<Mat<f64>, BdfError> {
        self.cols(n, n)
    }
    fn cols(&mut self, rows: usize, cols: usize) -> Result<Mat<f64>, BdfError> {
        let mut m = Mat::zeros(rows, cols);
        for j in 0..cols {
            let col = self.vec(rows)?;
            m.col_as_slice_mut(j).copy_from_slice(&col);
        }
        Ok(m)
    }
}
