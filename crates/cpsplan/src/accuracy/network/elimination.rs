//! The square-root information form of the network's least squares, updated one
//! event at a time: an upper-triangular factor `R` (with its right-hand side)
//! over the *active* unknowns (the parent's current station, the children's
//! current points, every target), and for each unknown left behind the Gaussian
//! conditional it was eliminated into (`R_j x_j + S x_sep = d`, one block row of
//! the network's factor). A measurement adds whitened rows, folded into `R` by a
//! QR factorisation before the next elimination or query; eliminating an
//! unknown is one QR of the active factor with its columns first. Nothing
//! already factored changes: the cost is `O(d³)` per elimination, `d` the active
//! dimension, whatever the network's size.
//!
//! Why QR and not the normal equations: the information `RᵀR` of a long CPS
//! chain spans micro-radian relative constraints and metres of absolute drift,
//! and forming it squares that condition number (relative errors of 10⁻⁶ after a
//! few hundred cycles); the square-root form keeps it (10⁻¹¹).

use nalgebra::{DMatrix, DVector};

/// One eliminated unknown: `R δx_j + S δx_sep = d`, with `R` upper triangular.
#[derive(Debug, Clone)]
pub(crate) struct Conditional {
    /// The unknown.
    pub var: usize,
    /// `R⁻¹`.
    pub r_inv: DMatrix<f64>,
    /// `S`, one column block per separator unknown.
    pub s: DMatrix<f64>,
    /// The separator: the active unknowns it was coupled to, with the first
    /// column of each in `s`.
    pub sep: Vec<(usize, usize)>,
    /// `d`.
    pub d: DVector<f64>,
}

/// Why an unknown cannot be eliminated or the active set solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Singular {
    /// The unknown whose information is not positive definite (`None`: the
    /// active set as a whole).
    pub var: Option<usize>,
}

/// Whitened measurement rows: a Jacobian block per unknown, and the right-hand
/// side.
type Rows = (Vec<(usize, DMatrix<f64>)>, DVector<f64>);

/// The active factor, the measurement rows not folded in yet, and the
/// conditionals so far.
#[derive(Debug, Clone, Default)]
pub(crate) struct Elimination {
    /// Active unknowns in order, with their dimension.
    pub active: Vec<(usize, usize)>,
    /// Offset of each active unknown (parallel to `active`).
    offsets: Vec<usize>,
    /// Position in `active` of every unknown id (`None`: not active).
    slot: Vec<Option<usize>>,
    /// `[R | r]`: the upper-triangular factor of the active unknowns and its
    /// right-hand side, `d × (d + 1)`.
    factor: DMatrix<f64>,
    /// Whitened rows `[A | b]` not folded into the factor yet.
    pending: Vec<Rows>,
    /// The eliminated unknowns, in order.
    pub conditionals: Vec<Conditional>,
}

impl Elimination {
    /// The active dimension.
    fn dim(&self) -> usize {
        self.factor.nrows()
    }

    /// Makes unknown `var` of dimension `dim` active, with no information yet.
    pub fn add(&mut self, var: usize, dim: usize) {
        self.fold();
        if self.slot.len() <= var {
            self.slot.resize(var + 1, None);
        }
        let n = self.dim();
        self.slot[var] = Some(self.active.len());
        self.active.push((var, dim));
        self.offsets.push(n);
        // Insert `dim` zero columns before the right-hand side, and zero rows.
        let mut f = DMatrix::zeros(n + dim, n + dim + 1);
        f.view_mut((0, 0), (n, n))
            .copy_from(&self.factor.view((0, 0), (n, n)));
        for i in 0..n {
            f[(i, n + dim)] = self.factor[(i, n)];
        }
        self.factor = f;
    }

    /// The offset of active unknown `var`.
    pub fn offset(&self, var: usize) -> Option<usize> {
        let s = (*self.slot.get(var)?)?;
        Some(self.offsets[s])
    }

    /// Adds a measurement with Jacobian blocks `blocks` (active unknown, block),
    /// diagonal noise variances `variance` and residual `r`, as whitened rows.
    pub fn add_measurement(
        &mut self,
        blocks: &[(usize, DMatrix<f64>)],
        variance: &DVector<f64>,
        r: &DVector<f64>,
    ) {
        let k = r.len();
        let scale: Vec<f64> = (0..k)
            .map(|i| {
                if variance[i] > 0.0 {
                    1.0 / variance[i].sqrt()
                } else {
                    0.0
                }
            })
            .collect();
        let rows: Vec<(usize, DMatrix<f64>)> = blocks
            .iter()
            .filter(|(v, _)| self.offset(*v).is_some())
            .map(|(v, h)| {
                (
                    *v,
                    DMatrix::from_fn(k, h.ncols(), |i, j| h[(i, j)] * scale[i]),
                )
            })
            .collect();
        let b = DVector::from_fn(k, |i, _| r[i] * scale[i]);
        self.pending.push((rows, b));
    }

    /// Adds a prior `N(δ, σ² I)` on active unknown `var`.
    pub fn add_prior(&mut self, var: usize, sigma: f64, delta: &DVector<f64>) {
        let n = delta.len();
        let block = DMatrix::identity(n, n) / sigma;
        self.pending.push((vec![(var, block)], delta / sigma));
    }

    /// Folds the pending rows into the factor: QR of `[R | r; A | b]`.
    pub fn fold(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let n = self.dim();
        let extra: usize = self.pending.iter().map(|p| p.1.len()).sum();
        let mut m = DMatrix::zeros(n + extra, n + 1);
        m.view_mut((0, 0), (n, n + 1)).copy_from(&self.factor);
        let mut row = n;
        for (blocks, b) in std::mem::take(&mut self.pending) {
            let k = b.len();
            for (v, h) in &blocks {
                if let Some(o) = self.offset(*v) {
                    m.view_mut((row, o), (k, h.ncols())).copy_from(h);
                }
            }
            m.view_mut((row, n), (k, 1)).copy_from(&b);
            row += k;
        }
        self.factor = triangular(m, n);
    }

    /// Eliminates active unknown `var` into its conditional.
    pub fn eliminate(&mut self, var: usize) -> Result<(), Singular> {
        self.fold();
        let Some(slot) = self.slot.get(var).copied().flatten() else {
            return Ok(());
        };
        let (_, dim) = self.active[slot];
        let o = self.offsets[slot];
        let n = self.dim();
        // Columns with the unknown's first, then the rest, then the right-hand side.
        let order: Vec<usize> = (o..o + dim)
            .chain((0..n).filter(|&i| i < o || i >= o + dim))
            .chain(std::iter::once(n))
            .collect();
        let m = DMatrix::from_fn(n, n + 1, |i, j| self.factor[(i, order[j])]);
        let t = triangular(m, n);
        let rjj = t.view((0, 0), (dim, dim)).into_owned();
        let r_inv = upper_inverse(&rjj).ok_or(Singular { var: Some(var) })?;
        let s_full = t.view((0, dim), (dim, n - dim)).into_owned();
        let d = t.view((0, n), (dim, 1)).column(0).into_owned();
        // The separator: the active unknowns with a coupling.
        let mut sep = Vec::new();
        let mut columns = Vec::new();
        let mut k0 = 0;
        for (s, &(v, dv)) in self.active.iter().enumerate() {
            if s == slot {
                continue;
            }
            if s_full.columns(k0, dv).iter().any(|&x| x != 0.0) {
                sep.push((v, columns.len()));
                columns.extend(k0..k0 + dv);
            }
            k0 += dv;
        }
        let s = DMatrix::from_fn(dim, columns.len(), |i, k| s_full[(i, columns[k])]);
        self.conditionals.push(Conditional {
            var,
            r_inv,
            s,
            sep,
            d,
        });
        let rest = n - dim;
        self.factor = t.view((dim, dim), (rest, rest + 1)).into_owned();
        self.active.remove(slot);
        self.slot[var] = None;
        self.offsets.clear();
        let mut off = 0;
        for (i, &(v, dv)) in self.active.iter().enumerate() {
            self.slot[v] = Some(i);
            self.offsets.push(off);
            off += dv;
        }
        Ok(())
    }

    /// The covariance of the active unknowns, `R⁻¹R⁻ᵀ`, and their solution
    /// `R⁻¹ r` (the pending rows folded in first: [`Self::fold`]).
    pub fn solve_active(&self) -> Result<(DMatrix<f64>, DVector<f64>), Singular> {
        if !self.pending.is_empty() {
            let mut folded = self.clone();
            folded.fold();
            return folded.solve_active();
        }
        let n = self.dim();
        if n == 0 {
            return Ok((DMatrix::zeros(0, 0), DVector::zeros(0)));
        }
        let r = self.factor.view((0, 0), (n, n)).into_owned();
        let r_inv = upper_inverse(&r).ok_or(Singular { var: None })?;
        let x = &r_inv * self.factor.column(n);
        let cov = &r_inv * r_inv.transpose();
        Ok(((&cov + cov.transpose()) * 0.5, x))
    }
}

/// The upper-triangular `n × (n + 1)` factor `[R | r]` of `m`'s rows (QR by
/// Householder reflections; `m` has at least `n` rows or is padded).
fn triangular(m: DMatrix<f64>, n: usize) -> DMatrix<f64> {
    let rows = m.nrows();
    let m = if rows < n + 1 {
        m.resize_vertically(n + 1, 0.0)
    } else {
        m
    };
    let r = m.qr().r();
    let mut out = DMatrix::zeros(n, n + 1);
    let take = r.nrows().min(n);
    out.view_mut((0, 0), (take, n + 1))
        .copy_from(&r.view((0, 0), (take, n + 1)));
    // Below the diagonal the reflections leave exact zeros; make sure.
    for i in 0..n {
        for j in 0..i.min(n + 1) {
            out[(i, j)] = 0.0;
        }
    }
    out
}

/// The inverse of an upper-triangular matrix, `None` when a pivot is zero or
/// negligible against the largest.
fn upper_inverse(r: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = r.nrows();
    let big = (0..n).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    if n == 0 {
        return Some(DMatrix::zeros(0, 0));
    }
    if (0..n)
        .any(|i| r[(i, i)].abs().partial_cmp(&(big * 1e-14)) != Some(std::cmp::Ordering::Greater))
    {
        return None;
    }
    let mut inv = DMatrix::zeros(n, n);
    for c in 0..n {
        for i in (0..=c).rev() {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for k in i + 1..=c {
                s -= r[(i, k)] * inv[(k, c)];
            }
            inv[(i, c)] = s / r[(i, i)];
        }
    }
    Some(inv)
}
