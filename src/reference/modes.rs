//! The active-set search for the contact mode (paper Eqs. 18–20 at acceleration
//! level): among the closed contacts that neither approach nor separate, find
//! which press (F_n > 0, δ̈ = 0), which lift off (F_n = 0, δ̈ ≥ 0), which stick
//! (v̇_t = 0, |F_t| ≤ μ_s F_n) and which slide (F_t = −μ F_n sgn v_t).

use super::dynamics::{Active, Dynamics, Mode, RowConst, View};

/// A closed, non-approaching contact: slot of block, and its v_t (m/s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    pub block: usize,
    pub slot: usize,
    pub vt: f64,
}

/// Tolerances of the search (SI units).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ModeTol {
    /// Force tolerance (N): F_n < −force means lift-off.
    pub force: f64,
    /// Acceleration tolerance (m/s²): δ̈ < −accel means the contact must press.
    pub accel: f64,
    /// Velocity tolerance (m/s): |v_t| ≤ velocity counts as sticking.
    pub velocity: f64,
}

pub(crate) fn initial_mode(rc: &RowConst, slot: usize, vt: f64, tol: &ModeTol) -> Mode {
    let (mu, mus) = rc.mu(slot);
    if mus == f64::INFINITY {
        // no slip: a closing contact sticks at once (the impact or the
        // projection stops its slip)
        Mode::Stick
    } else if vt.abs() <= tol.velocity && mus > 0.0 {
        Mode::Stick
    } else if mu > 0.0 {
        Mode::Slide(vt.signum())
    } else {
        Mode::Frictionless
    }
}

/// Finds the mode; `out` receives the pressing contacts, in candidate order
/// (which must be sorted by block). Returns false if no consistent mode was
/// found within the iteration limit: the last one tried is kept, less the
/// contacts whose normal force pulls (they lift off).
pub(crate) fn select(
    dyn_: &mut Dynamics,
    rc: &RowConst,
    view: &View,
    candidates: &[Candidate],
    state: &mut Vec<Option<Mode>>,
    out: &mut Vec<Active>,
    tol: &ModeTol,
) -> bool {
    state.clear();
    state.extend(
        candidates
            .iter()
            .map(|c| Some(initial_mode(rc, c.slot, c.vt, tol))),
    );
    for iter in 0..200 {
        out.clear();
        for (c, m) in candidates.iter().zip(state.iter()) {
            if let Some(mode) = m {
                out.push(Active {
                    block: c.block,
                    slot: c.slot,
                    mode: *mode,
                });
            }
        }
        if !dyn_.forces(rc, view, out) {
            return false;
        }
        // violations: (size, candidate index, new state)
        let mut worst: Option<(f64, usize, Option<Mode>)> = None;
        let mut all: u32 = 0;
        let mut changes: [(usize, Option<Mode>); 64] = [(0, None); 64];
        let mut k = 0;
        for (ci, (c, m)) in candidates.iter().zip(state.iter()).enumerate() {
            let change = match m {
                Some(mode) => {
                    let fnn = dyn_.fn_[k];
                    let ft = dyn_.ft[k];
                    k += 1;
                    let (mu, mus) = rc.mu(c.slot);
                    if fnn < -tol.force {
                        Some((-fnn, None))
                    } else if *mode == Mode::Stick
                        && rc.stick_excess(c.slot, ft, fnn.max(0.0)) > tol.force
                    {
                        let next = if mu > 0.0 {
                            Mode::Slide(-ft.signum())
                        } else {
                            Mode::Frictionless
                        };
                        Some((ft.abs() - mus * fnn, Some(next)))
                    } else {
                        None
                    }
                }
                None => {
                    let g = rc.geom(view, c.block, c.slot).expect("slot exists");
                    let kk = rc.kin(view, &g);
                    let gdd = dyn_.gddot(view, &g, &kk);
                    if gdd < -tol.accel {
                        let m = rc.p.block.mass;
                        Some((-gdd * m, Some(initial_mode(rc, c.slot, c.vt, tol))))
                    } else {
                        None
                    }
                }
            };
            if let Some((size, next)) = change {
                if worst.is_none_or(|w| size > w.0) {
                    worst = Some((size, ci, next));
                }
                if (all as usize) < changes.len() {
                    changes[all as usize] = (ci, next);
                }
                all += 1;
            }
        }
        let Some((_, ci, next)) = worst else {
            return true;
        };
        if iter < 6 && (all as usize) <= changes.len() {
            for &(ci, next) in &changes[..all as usize] {
                state[ci] = next;
            }
        } else {
            state[ci] = next;
        }
    }
    // No consistent mode (the search cycles, as frictional contact problems
    // can). Never keep a contact that pulls: a pulling contact would call
    // for a lift-off event at every step and stall the run. Let such
    // contacts lift off (if they then close again, that is an event) and
    // keep the rest of the last mode.
    for _ in 0..out.len() {
        let Some(worst) = (0..out.len())
            .filter(|&k| dyn_.fn_[k] < -tol.force)
            .min_by(|&a, &b| dyn_.fn_[a].total_cmp(&dyn_.fn_[b]))
        else {
            break;
        };
        out.remove(worst);
        if !dyn_.forces(rc, view, out) {
            break;
        }
    }
    false
}
