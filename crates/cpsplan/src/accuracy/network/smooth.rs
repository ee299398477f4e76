//! The smoothing pass: from the active unknowns' joint covariance, back through
//! the conditionals in reverse order of elimination, the marginal covariance and
//! the solution of every unknown given every measurement (the
//! Rauch–Tung–Striebel recursion in square-root information form).
//!
//! For a conditional `R x_j + S x_sep = d`: `x_j = R⁻¹(d − S x_sep)`, so with
//! `K = R⁻¹ S`, `Σ_{j,·} = −K Σ_{sep,·}` and `Σ_jj = R⁻¹R⁻ᵀ + K Σ_{sep,sep} Kᵀ`.
//! The pass keeps the joint covariance of the unknowns some earlier conditional
//! still needs (as many as were active when it was eliminated), so its cost is
//! linear in the network's size.

use nalgebra::{DMatrix, DVector};

use super::elimination::{Elimination, Singular};

/// The smoothed marginals: per unknown its covariance and its correction to the
/// linearisation point, and per pair of unknowns that share a measurement their
/// cross-covariance.
#[derive(Debug, Clone, Default)]
pub(crate) struct Marginals {
    /// Per unknown id (`None`: fixed or never seen).
    pub cov: Vec<Option<DMatrix<f64>>>,
    /// Per unknown id.
    pub delta: Vec<Option<DVector<f64>>>,
    /// Cross-covariance `Σ_ab` of the pairs asked for, `(a, b)` with `a` the
    /// one listed first in the request.
    pub cross: std::collections::HashMap<(usize, usize), DMatrix<f64>>,
}

/// The joint covariance of the unknowns still needed.
struct Live {
    vars: Vec<(usize, usize)>,
    slot: Vec<Option<usize>>,
    offsets: Vec<usize>,
    cov: DMatrix<f64>,
    delta: DVector<f64>,
}

impl Live {
    fn index(&self, var: usize) -> Option<(usize, usize)> {
        let s = (*self.slot.get(var)?)?;
        Some((self.offsets[s], self.vars[s].1))
    }

    fn rebuild_offsets(&mut self) {
        self.offsets.clear();
        let mut o = 0;
        for (i, &(v, d)) in self.vars.iter().enumerate() {
            self.slot[v] = Some(i);
            self.offsets.push(o);
            o += d;
        }
    }

    fn push(&mut self, var: usize, cross: DMatrix<f64>, own: DMatrix<f64>, delta: DVector<f64>) {
        let n = self.cov.nrows();
        let d = own.nrows();
        let mut cov = std::mem::take(&mut self.cov).resize(n + d, n + d, 0.0);
        cov.view_mut((n, 0), (d, n)).copy_from(&cross);
        cov.view_mut((0, n), (n, d)).copy_from(&cross.transpose());
        cov.view_mut((n, n), (d, d)).copy_from(&own);
        self.cov = cov;
        self.delta = std::mem::take(&mut self.delta).resize_vertically(n + d, 0.0);
        self.delta.rows_mut(n, d).copy_from(&delta);
        self.vars.push((var, d));
        self.rebuild_offsets();
    }

    fn drop_vars(&mut self, gone: &[usize]) {
        if gone.is_empty() {
            return;
        }
        let mut keep = Vec::new();
        let mut vars = Vec::new();
        for (i, &(v, d)) in self.vars.iter().enumerate() {
            if gone.contains(&v) {
                self.slot[v] = None;
            } else {
                keep.extend(self.offsets[i]..self.offsets[i] + d);
                vars.push((v, d));
            }
        }
        self.cov = DMatrix::from_fn(keep.len(), keep.len(), |i, j| self.cov[(keep[i], keep[j])]);
        self.delta = DVector::from_fn(keep.len(), |i, _| self.delta[keep[i]]);
        self.vars = vars;
        self.rebuild_offsets();
    }
}

/// The smoothed marginals of every unknown of `elim` (`vars` unknowns in all);
/// `pairs[v]` lists the unknowns whose cross-covariance with `v` is wanted.
pub(crate) fn smooth(
    elim: &Elimination,
    vars: usize,
    pairs: &[Vec<usize>],
) -> Result<Marginals, Singular> {
    let (root_cov, root_delta) = elim.solve_active()?;
    let conds = &elim.conditionals;
    // The last conditional (lowest index) whose separator holds each unknown.
    let mut first_use: Vec<Option<usize>> = vec![None; vars];
    for (i, c) in conds.iter().enumerate() {
        for &(v, _) in &c.sep {
            if first_use[v].is_none() {
                first_use[v] = Some(i);
            }
        }
    }
    let mut out = Marginals {
        cov: vec![None; vars],
        delta: vec![None; vars],
        cross: Default::default(),
    };
    let mut live = Live {
        vars: elim.active.clone(),
        slot: vec![None; vars],
        offsets: Vec::new(),
        cov: root_cov,
        delta: root_delta,
    };
    live.rebuild_offsets();
    for &(v, d) in &elim.active {
        let (o, _) = live.index(v).expect("active");
        out.cov[v] = Some(live.cov.view((o, o), (d, d)).into_owned());
        out.delta[v] = Some(live.delta.rows(o, d).into_owned());
    }
    record_pairs(&live, &elim.active, pairs, &mut out);
    let unused: Vec<usize> = elim
        .active
        .iter()
        .map(|a| a.0)
        .filter(|&v| first_use[v].is_none())
        .collect();
    live.drop_vars(&unused);
    let mut drops: Vec<Vec<usize>> = vec![Vec::new(); conds.len()];
    for (v, f) in first_use.iter().enumerate() {
        if let Some(i) = f {
            drops[*i].push(v);
        }
    }
    for (i, c) in conds.iter().enumerate().rev() {
        let mut idx = Vec::new();
        for &(v, _) in &c.sep {
            let (o, d) = live.index(v).ok_or(Singular { var: Some(v) })?;
            idx.extend(o..o + d);
        }
        let dim = c.r_inv.nrows();
        let k = &c.r_inv * &c.s;
        let sep_live = DMatrix::from_fn(idx.len(), live.cov.ncols(), |a, b| live.cov[(idx[a], b)]);
        let cross = -(&k * sep_live);
        let cross_sep = DMatrix::from_fn(dim, idx.len(), |a, b| cross[(a, idx[b])]);
        let own = &c.r_inv * c.r_inv.transpose() - cross_sep * k.transpose();
        let own = (&own + own.transpose()) * 0.5;
        let sep_delta = DVector::from_fn(idx.len(), |a, _| live.delta[idx[a]]);
        let delta = &c.r_inv * &c.d - &k * sep_delta;
        out.cov[c.var] = Some(own.clone());
        out.delta[c.var] = Some(delta.clone());
        live.push(c.var, cross, own, delta);
        record_pairs(&live, &[(c.var, dim)], pairs, &mut out);
        let mut gone = std::mem::take(&mut drops[i]);
        if first_use[c.var].is_none_or(|f| f >= i) {
            gone.push(c.var);
        }
        live.drop_vars(&gone);
    }
    Ok(out)
}

/// Records the cross-covariances of `new` unknowns with the live ones asked for.
fn record_pairs(live: &Live, new: &[(usize, usize)], pairs: &[Vec<usize>], out: &mut Marginals) {
    for &(v, dv) in new {
        let Some(list) = pairs.get(v) else { continue };
        let Some((ov, _)) = live.index(v) else {
            continue;
        };
        for &w in list {
            if out.cross.contains_key(&(v, w)) || out.cross.contains_key(&(w, v)) {
                continue;
            }
            let Some((ow, dw)) = live.index(w) else {
                continue;
            };
            out.cross
                .insert((v, w), live.cov.view((ov, ow), (dv, dw)).into_owned());
        }
    }
}
