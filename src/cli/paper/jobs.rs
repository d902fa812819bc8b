//! The runs behind each figure of `topple paper`: one function per figure,
//! each a list of [`Job`]s (row, settings, and where the result goes).
//!
//! | figure | rows (reference engine) |
//! | --- | --- |
//! | 3 | Domino X, Table 1, s/h 0.18, pushes 1.8 and 0.5 |
//! | 4 | Domino T and P, Table 1, across the spacings |
//! | 5 | ideal Domino T, μ1 = 0 and 0.15, across the spacings |
//! | `fig5_ground` | ideal Domino T on each ground law ([`ground_variants`]) |
//! | 6, 7 | Domino X, s/h 0.52, Table 1 and ideal, 20 blocks with time series |
//! | 8 | Domino X, s/h 0.52, Table 1 and ideal, pushes 0.5, 1, 1.8 |
//! | 9 | Domino X, μ2 = 0.9, e2 = 0: μ1 (a) and e1 (b) at three spacings |
//! | 10 | Domino X, μ1 = e1 = 0: μ2 (a) and e2 (b) at three spacings |

use topple::domino::{Ground, Preset, RowParams, RowSpec};
use topple::reference::Settings;

/// Job id of the figure `fig5_ground`.
pub const GROUND_FIG: u32 = 50;
/// Friction between blocks of the second set of rows in `fig5_ground`.
pub const GROUND_MU1: f64 = 0.15;
/// The three spacings s/h of Figs. 9 and 10.
const THREE_SPACINGS: [f64; 3] = [0.18, 0.35, 0.52];
/// Blocks of the time-series rows of Figs. 6 and 7.
const SERIES_BLOCKS: usize = 20;

/// One reference-engine run and where its result goes.
pub struct Job {
    /// Figure id (3..=10, or [`GROUND_FIG`]).
    pub fig: u32,
    /// Curve key within the figure.
    pub key: String,
    /// x coordinate in the figure (parameter value) when it is a sweep.
    pub x: f64,
    pub row: RowSpec,
    pub settings: Settings,
}

/// What every figure's jobs share: the row length, the spacings of the
/// sweeps and the base settings.
pub struct Plan<'a> {
    pub n: usize,
    pub spacings: &'a [f64],
    pub base: &'a Settings,
}

impl Plan<'_> {
    /// A job on a row of `n` blocks of `p` at spacing ratio `sh` (s/h).
    #[allow(clippy::too_many_arguments)]
    fn job(
        &self,
        fig: u32,
        key: impl Into<String>,
        x: f64,
        p: RowParams,
        sh: f64,
        push: f64,
        n: usize,
        settings: &Settings,
    ) -> Job {
        Job {
            fig,
            key: key.into(),
            x,
            row: RowSpec::new(p, sh * p.block.height, n, push),
            settings: settings.clone(),
        }
    }

    /// A sweep point: `n` blocks, push 1, the base settings.
    fn point(&self, fig: u32, key: impl Into<String>, x: f64, p: RowParams, sh: f64) -> Job {
        self.job(fig, key, x, p, sh, 1.0, self.n, self.base)
    }

    /// The jobs of the figures `want` accepts, in figure order.
    pub fn jobs(&self, want: impl Fn(u32) -> bool) -> Vec<Job> {
        let mut jobs = Vec::new();
        if want(3) {
            jobs.extend(self.fig3());
        }
        if want(4) {
            jobs.extend(self.fig4());
        }
        if want(5) {
            jobs.extend(self.fig5());
            jobs.extend(self.fig5_ground());
        }
        if want(6) || want(7) {
            jobs.extend(self.fig7());
        }
        if want(8) {
            jobs.extend(self.fig8());
        }
        if want(9) {
            jobs.extend(self.fig9());
        }
        if want(10) {
            jobs.extend(self.fig10());
        }
        jobs
    }

    fn fig3(&self) -> Vec<Job> {
        let x = Preset::X.params();
        [1.8, 0.5]
            .map(|push| {
                self.job(
                    3,
                    format!("push {push}"),
                    0.0,
                    x,
                    0.18,
                    push,
                    self.n,
                    self.base,
                )
            })
            .into()
    }

    fn fig4(&self) -> Vec<Job> {
        let mut v = Vec::new();
        for (name, pr) in [("T", Preset::T), ("P", Preset::P)] {
            for &sh in self.spacings {
                v.push(self.point(4, name, sh, pr.params(), sh));
            }
        }
        v
    }

    fn fig5(&self) -> Vec<Job> {
        let ideal = Preset::T.params().ideal();
        let mut v = Vec::new();
        for &sh in self.spacings {
            v.push(self.point(5, "mu1 = 0, e1 = 0", sh, ideal, sh));
            v.push(self.point(5, "mu1 = 0.15, e1 = 0", sh, set_mu1(ideal, 0.15), sh));
        }
        v
    }

    fn fig5_ground(&self) -> Vec<Job> {
        let mut v = Vec::new();
        for (name, p) in ground_variants() {
            for &sh in self.spacings {
                v.push(self.point(GROUND_FIG, name.clone(), sh, p, sh));
            }
        }
        v
    }

    /// Figs. 6 and 7 share these runs (Fig. 6 adds snapshots in a second pass).
    fn fig7(&self) -> Vec<Job> {
        let series = Settings {
            series_blocks: vec![7, 8, 9, 10],
            series_interval: 2e-4,
            ..self.base.clone()
        };
        let x = Preset::X.params();
        [("Table 1", x), ("ideal", x.ideal())]
            .map(|(key, p)| self.job(7, key, 0.0, p, 0.52, 1.0, SERIES_BLOCKS, &series))
            .into()
    }

    fn fig8(&self) -> Vec<Job> {
        let x = Preset::X.params();
        let mut v = Vec::new();
        for push in [0.5, 1.0, 1.8] {
            for (name, p) in [("Table 1", x), ("ideal", x.ideal())] {
                let key = format!("{name}, push {push}");
                v.push(self.job(8, key, 0.0, p, 0.52, push, self.n, self.base));
            }
        }
        v
    }

    fn fig9(&self) -> Vec<Job> {
        let g = with_ground_ideal(Preset::X.params());
        let mut v = Vec::new();
        for sh in THREE_SPACINGS {
            for mu1 in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5] {
                let p = RowParams {
                    e1: 0.0,
                    ..set_mu1(g, mu1)
                };
                v.push(self.point(9, format!("a s/h {sh}"), mu1, p, sh));
            }
            for e1 in [0.0, 0.2, 0.4, 0.6, 0.8, 0.9] {
                let p = RowParams {
                    e1,
                    ..set_mu1(g, 0.0)
                };
                v.push(self.point(9, format!("b s/h {sh}"), e1, p, sh));
            }
        }
        v
    }

    fn fig10(&self) -> Vec<Job> {
        let x = Preset::X.params();
        let mut v = Vec::new();
        for sh in THREE_SPACINGS {
            for mu2 in [0.2, 0.3, 0.4, 0.5, 0.7, 0.9] {
                let p = RowParams {
                    e1: 0.0,
                    e2: 0.0,
                    ..set_mu2(set_mu1(x, 0.0), mu2)
                };
                v.push(self.point(10, format!("a s/h {sh}"), mu2, p, sh));
            }
            for e2 in [0.0, 0.2, 0.4, 0.6, 0.8] {
                let p = RowParams {
                    e1: 0.0,
                    e2,
                    ..set_mu1(with_ground_ideal(x), 0.0)
                };
                v.push(self.point(10, format!("b s/h {sh}"), e2, p, sh));
            }
        }
        v
    }
}

/// The ground of the paper's ideal rows: μ2 = 0.9 (sliding and sticking), e2 = 0.
fn with_ground_ideal(p: RowParams) -> RowParams {
    RowParams {
        mu2: 0.9,
        mu2_stick: 0.9,
        e2: 0.0,
        ..p
    }
}

/// Friction between blocks μ1, sliding and sticking.
fn set_mu1(p: RowParams, mu: f64) -> RowParams {
    RowParams {
        mu1: mu,
        mu1_stick: mu,
        ..p
    }
}

/// Friction at the ground μ2, sliding and sticking.
fn set_mu2(p: RowParams, mu: f64) -> RowParams {
    RowParams {
        mu2: mu,
        mu2_stick: mu,
        ..p
    }
}

/// The rows of `fig5_ground`: the ideal Domino T row with μ1 = 0 and 0.15,
/// each on a no-slip ground, with the paper's halved impact friction and
/// with full impact friction (μ2 = 0.9 in and out of impacts). The no-slip
/// rows keep μ1 at full value inside impacts too, as the extended model
/// assumes. Curve names hold no commas (they go into a CSV header).
pub fn ground_variants() -> Vec<(String, RowParams)> {
    let ideal = Preset::T.params().ideal();
    let mut v = Vec::new();
    for mu1 in [0.0, GROUND_MU1] {
        let p = set_mu1(ideal, mu1);
        let full = RowParams {
            impact_friction_factor: 1.0,
            ..p
        };
        let no_slip = RowParams {
            ground: Ground::NoSlip,
            ..full
        };
        v.push((format!("no-slip ground; mu1 = {mu1}"), no_slip));
        v.push((format!("halved impact friction; mu1 = {mu1}"), p));
        v.push((format!("full impact friction; mu1 = {mu1}"), full));
    }
    v
}
