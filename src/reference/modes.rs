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

/// A hash of a mode assignment (FNV-1a over one code per candidate).
fn state_key(state: &[Option<Mode>]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for m in state {
        let code = match m {
            None => 0u64,
            Some(Mode::Frictionless) => 1,
            Some(Mode::Stick) => 2,
            Some(Mode::Slide(d)) if *d > 0.0 => 3,
            Some(Mode::Slide(_)) => 4,
        };
        h = (h ^ code).wrapping_mul(0x0100_0000_01b3);
    }
    h
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

/// The violations of a mode: the largest (its size, the candidate, the
/// state that candidate should take) and the first 64 of them.
struct Assessment {
    worst: Option<(f64, usize, Option<Mode>)>,
    all: usize,
    changes: [(usize, Option<Mode>); 64],
}

/// Puts the pressing contacts of `state` into `out`, computes their forces
/// and checks every candidate: a pressing contact must not pull nor stick
/// beyond its cone, a free one must not be driven into its face. `None` if
/// the contact system is singular.
fn assess(
    dyn_: &mut Dynamics,
    rc: &RowConst,
    view: &View,
    candidates: &[Candidate],
    state: &[Option<Mode>],
    out: &mut Vec<Active>,
    tol: &ModeTol,
) -> Option<Assessment> {
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
        return None;
    }
    let mut a = Assessment {
        worst: None,
        all: 0,
        changes: [(0, None); 64],
    };
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
            if a.worst.is_none_or(|w| size > w.0) {
                a.worst = Some((size, ci, next));
            }
            if a.all < a.changes.len() {
                a.changes[a.all] = (ci, next);
            }
            a.all += 1;
        }
    }
    Some(a)
}

/// The modes candidate `c` may take when the search cycles: lifting off,
/// and pressing — sticking or sliding either way while it barely slips,
/// sliding along its slip when it slips. At most four.
fn options(rc: &RowConst, c: &Candidate, tol: &ModeTol) -> ([Option<Mode>; 4], usize) {
    let (mu, mus) = rc.mu(c.slot);
    let mut o = [None; 4];
    let mut n = 1;
    let barely = c.vt.abs() <= tol.velocity || mus == f64::INFINITY;
    let modes = [
        (barely && mus > 0.0, Mode::Stick),
        (barely && mu > 0.0 && mu.is_finite(), Mode::Slide(1.0)),
        (barely && mu > 0.0 && mu.is_finite(), Mode::Slide(-1.0)),
        (!barely && mu > 0.0, Mode::Slide(c.vt.signum())),
    ];
    for (allowed, m) in modes {
        if allowed && n < o.len() {
            o[n] = Some(m);
            n += 1;
        }
    }
    if n == 1 {
        o[1] = Some(Mode::Frictionless);
        n = 2;
    }
    (o, n)
}

/// How [`select`] ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Search {
    /// A consistent mode (Eqs. 18–20 hold within the tolerances).
    Consistent,
    /// The contact system was singular; `out` holds the last mode tried.
    Singular,
    /// No consistent mode: the last one tried, its pulling contacts lifted
    /// off or sliding, its overloaded stuck contacts sliding. The events of
    /// the next steps correct it.
    Relaxed,
    /// As [`Search::Relaxed`], and a sliding contact that pulled presses
    /// without friction (Painlevé's case): a stop-gap no event ends, so the
    /// engine searches again after the next step.
    Frictionless,
}

/// Finds the mode; `out` receives the pressing contacts, in candidate order
/// (which must be sorted by block). If no consistent mode is found, the
/// last one tried is kept with every contact whose normal force pulls
/// relaxed one step at a time (a stuck one slides, a sliding one presses
/// without friction, a frictionless one lifts off) and the contacts that
/// stick beyond their cone sliding ([`Search`]).
///
/// The search changes the worst violation's contact one at a time (all of
/// them in the first six rounds). It is deterministic, so a state it has
/// tried before means it cycles — with friction, changing one contact can
/// undo another (a corner that pulls when it presses and is driven into the
/// ground when it does not): then every mode of the contacts in the cycle
/// (up to four of them) is tried with the others as they are.
pub(crate) fn select(
    dyn_: &mut Dynamics,
    rc: &RowConst,
    view: &View,
    candidates: &[Candidate],
    state: &mut Vec<Option<Mode>>,
    out: &mut Vec<Active>,
    tol: &ModeTol,
) -> Search {
    state.clear();
    state.extend(
        candidates
            .iter()
            .map(|c| Some(initial_mode(rc, c.slot, c.vt, tol))),
    );
    // the states tried so far, hashed, and the candidates each round changed
    let mut tried = [0u64; 200];
    let mut changed = [(0u8, 0usize); 256];
    let mut n_changed = 0;
    let mut cycle: Option<usize> = None;
    for iter in 0..200 {
        let key = state_key(state);
        if let Some(first) = tried[..iter].iter().position(|k| *k == key) {
            cycle = Some(first);
            break;
        }
        tried[iter] = key;
        let Some(a) = assess(dyn_, rc, view, candidates, state, out, tol) else {
            return Search::Singular;
        };
        let Some((_, ci, next)) = a.worst else {
            return Search::Consistent;
        };
        let mut note = |ci: usize| {
            if n_changed < changed.len() {
                changed[n_changed] = (iter as u8, ci);
                n_changed += 1;
            }
        };
        if iter < 6 && a.all <= a.changes.len() {
            for &(ci, next) in &a.changes[..a.all] {
                state[ci] = next;
                note(ci);
            }
        } else {
            state[ci] = next;
            note(ci);
        }
    }
    if let Some(first) = cycle {
        // the contacts changed inside the cycle
        let mut set = [0usize; 4];
        let mut size = 0;
        let mut small = true;
        for &(it, ci) in &changed[..n_changed] {
            if (it as usize) < first || set[..size].contains(&ci) {
                continue;
            }
            if size == set.len() {
                small = false;
                break;
            }
            set[size] = ci;
            size += 1;
        }
        if small && size > 0 {
            let mut opts = [([None; 4], 1usize); 4];
            for (o, &ci) in opts.iter_mut().zip(&set[..size]) {
                *o = options(rc, &candidates[ci], tol);
            }
            let opts = &opts[..size];
            let combos: usize = opts.iter().map(|o| o.1).product();
            for mut code in 0..combos {
                for (&ci, (o, n)) in set[..size].iter().zip(opts) {
                    state[ci] = o[code % n];
                    code /= n;
                }
                match assess(dyn_, rc, view, candidates, state, out, tol) {
                    None => return Search::Singular,
                    Some(a) if a.worst.is_none() => return Search::Consistent,
                    Some(_) => {}
                }
            }
        }
    }
    // The relaxation's forces as a mode: pressing where F_n > 0, sticking
    // inside the cone, sliding against F_t on its edge (along the slip
    // where the contact slips).
    let mut forces = dyn_.take_relax_forces();
    dyn_.relaxed_forces(
        rc,
        view,
        candidates.iter().map(|c| (c.block, c.slot, c.vt)),
        tol.velocity,
        100,
        &mut forces,
    );
    for (m, (c, [fnn, ft])) in state.iter_mut().zip(candidates.iter().zip(&forces)) {
        let (mu, mus) = rc.mu(c.slot);
        *m = if *fnn <= tol.force {
            None
        } else if mus == f64::INFINITY
            || (c.vt.abs() <= tol.velocity && mus > 0.0 && ft.abs() < mus * fnn - tol.force)
        {
            Some(Mode::Stick)
        } else if mu > 0.0 {
            let dir = if c.vt.abs() > tol.velocity {
                c.vt.signum()
            } else {
                -ft.signum()
            };
            Some(Mode::Slide(dir))
        } else {
            Some(Mode::Frictionless)
        };
    }
    dyn_.keep_relax_forces(forces);
    match assess(dyn_, rc, view, candidates, state, out, tol) {
        None => return Search::Singular,
        Some(a) if a.worst.is_none() => return Search::Consistent,
        Some(_) => {}
    }
    // No consistent mode (the search cycles, as frictional contact problems
    // can). Never keep a contact that pulls, nor one that sticks beyond its
    // cone: either would call for an event at every step and stall the run
    // (a lift-off or stick → slip event fires as soon as the violation
    // grows). Relax the worst pulling contact by one step, else let the
    // worst overloaded sticking contact slide, and repeat; if a contact
    // that lifted off then closes again, that is an event of its own.
    //
    // A sliding contact that pulls is Painlevé's case (docs/stress.md, "A
    // sliding contact its friction pulls"): with the friction of sliding
    // its row of the contact problem has no solution with F_n ≥ 0. Lifting
    // it off (as before) lets it approach again at once, and an e = 0 train
    // then repeats that impact at one instant without end; pressing without
    // friction keeps it closed, and the search runs again after the step.
    for _ in 0..3 * out.len() + 1 {
        let pulling = (0..out.len())
            .filter(|&k| dyn_.fn_[k] < -tol.force)
            .min_by(|&a, &b| dyn_.fn_[a].total_cmp(&dyn_.fn_[b]));
        if let Some(k) = pulling {
            match out[k].mode {
                // a stuck contact that pulls slides first: its stick row may
                // be what pulls it (a stuck set can be nearly singular, its
                // forces far beyond the weights), and a stuck contact's
                // friction needs a normal force to bound it
                Mode::Stick if can_slide(rc, &out[k]) => {
                    out[k].mode = slide_against(rc, out[k].slot, dyn_.ft[k]);
                }
                // a sliding contact that pulls (Painlevé's case: the
                // friction of sliding drives the contact into tension)
                // presses without friction until the next search
                Mode::Slide(_) => out[k].mode = Mode::Frictionless,
                _ => {
                    out.remove(k);
                }
            }
        } else {
            let excess = |k: usize| rc.stick_excess(out[k].slot, dyn_.ft[k], dyn_.fn_[k]);
            let Some(k) = (0..out.len())
                .filter(|&k| out[k].mode == Mode::Stick && excess(k) > tol.force)
                .max_by(|&a, &b| excess(a).total_cmp(&excess(b)))
            else {
                break;
            };
            out[k].mode = slide_against(rc, out[k].slot, dyn_.ft[k]);
        }
        if !dyn_.forces(rc, view, out) {
            break;
        }
    }
    // a contact with friction left pressing without it
    if out
        .iter()
        .any(|a| a.mode == Mode::Frictionless && rc.mu(a.slot).0 > 0.0)
    {
        Search::Frictionless
    } else {
        Search::Relaxed
    }
}

/// Whether a pressing contact in [`Mode::Stick`] may slide instead (μ_s
/// finite: not a no-slip ground).
fn can_slide(rc: &RowConst, a: &Active) -> bool {
    a.mode == Mode::Stick && rc.mu(a.slot).1.is_finite()
}

/// The sliding mode of a contact whose stuck friction force was `ft` (N):
/// sliding against it, F_t = −dir μ F_n with dir = −sgn F_t; frictionless
/// where μ = 0.
fn slide_against(rc: &RowConst, slot: usize, ft: f64) -> Mode {
    if rc.mu(slot).0 > 0.0 {
        Mode::Slide(-ft.signum())
    } else {
        Mode::Frictionless
    }
}
