//! The combinations of the sweep: a seeded generator and what it draws.

use crate::domino::{Preset, RowParams, RowSpec};

/// SplitMix64 (Steele, Lea and Flood 2014): a small seeded generator whose
/// stream depends only on the seed, on every platform.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator for `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// One of `items`.
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[(self.next_u64() % items.len() as u64) as usize]
    }
}

/// Who runs a combination.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StressEngine {
    /// The reference engine.
    Reference,
    /// Rapier f64 with topple's impacts.
    RapierF64,
    /// Rapier f32 (bevy_rapier2d's build) with topple's impacts.
    RapierF32,
    /// Rapier f64 with its own impact response.
    Native,
    /// One free-body impact (a chain of balls and boxes, no gravity) through
    /// the resolver with the fallback policy.
    Impact,
}

impl StressEngine {
    /// Every engine, in the order of the table.
    pub const ALL: [StressEngine; 5] = [
        StressEngine::Reference,
        StressEngine::RapierF64,
        StressEngine::RapierF32,
        StressEngine::Native,
        StressEngine::Impact,
    ];

    /// Native Rapier is the baseline topple is measured against: its
    /// violations are printed next to topple's, never counted in the exit
    /// status.
    pub fn is_baseline(self) -> bool {
        self == StressEngine::Native
    }

    /// The engine of combination `index` (the engines take turns).
    pub fn of_combo(index: usize) -> StressEngine {
        StressEngine::ALL[index % StressEngine::ALL.len()]
    }

    /// The engine called `name` in the table, if any.
    pub fn by_name(name: &str) -> Option<StressEngine> {
        StressEngine::ALL.into_iter().find(|e| e.name() == name)
    }

    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            StressEngine::Reference => "reference",
            StressEngine::RapierF64 => "rapier-f64",
            StressEngine::RapierF32 => "rapier-f32",
            StressEngine::Native => "native",
            StressEngine::Impact => "impact",
        }
    }
}

/// One combination: a row, its run, and the perturbation of its blocks.
#[derive(Clone, Debug, PartialEq)]
pub struct Combo {
    /// Index in the sweep (with the seed, it reproduces the combination).
    pub index: usize,
    /// The engine.
    pub engine: StressEngine,
    /// Preset name (X, T, P).
    pub preset: char,
    /// The row (preset, materials, s, n, push).
    pub row: RowSpec,
    /// Time step (s).
    pub dt: f64,
    /// Per block: shift of x (m) and forward tilt about the front bottom
    /// edge (rad) (Rapier engines; the reference engine takes the row as
    /// specified).
    pub perturbation: Vec<(f64, f64)>,
    /// Seed of the free-body impact (engine `Impact`).
    pub impact_seed: u64,
}

/// Draws combination `index` of the sweep with `seed`; rows have
/// `n_lo..=n_hi` blocks. Each combination has its own generator (seed and
/// index), so that one can be drawn again alone.
pub fn draw(seed: u64, index: usize, n_lo: usize, n_hi: usize) -> Combo {
    let mut g = SplitMix64::new(seed ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
    g.next_u64();
    let engine = StressEngine::of_combo(index);
    let (preset, p) = match g.pick(&['X', 'T', 'P']) {
        'X' => ('X', Preset::X.params()),
        'T' => ('T', Preset::T.params()),
        _ => ('P', Preset::P.params()),
    };
    let mut p: RowParams = if g.unit() < 0.3 { p.ideal() } else { p };
    if g.unit() < 0.7 {
        p.mu1 = g.range(0.0, 0.6);
        p.mu1_stick = p.mu1 * g.range(1.0, 1.3);
        p.e1 = g.pick(&[0.0, 0.3, 0.6, 0.9, 1.0]);
        p.mu2 = g.range(0.2, 1.0);
        p.mu2_stick = p.mu2 * g.range(1.0, 1.3);
        p.e2 = g.pick(&[0.0, 0.2, 0.5, 1.0]);
    }
    let spacing_ratio = g.range(0.1, 0.6);
    let n = n_lo + (g.next_u64() % (n_hi - n_lo + 1) as u64) as usize;
    let push = g.range(0.5, 2.0);
    let dt = match engine {
        StressEngine::Reference => g.pick(&[1e-4, 2e-4, 5e-4]),
        _ => g.pick(&[1.0 / 60.0, 1.0 / 120.0, 1.0 / 240.0, 1e-3]),
    };
    let s = spacing_ratio * p.block.height;
    let perturbation = (0..n)
        .map(|_| (g.range(-0.05, 0.05) * s, g.range(0.0, 0.005)))
        .collect();
    Combo {
        index,
        engine,
        preset,
        row: RowSpec::new(p, s, n, push),
        dt,
        perturbation,
        impact_seed: g.next_u64(),
    }
}

/// The command line that runs this combination alone.
pub fn reproduce(seed: u64, index: usize, full: bool) -> String {
    format!(
        "topple stress --seed {seed} --combo {index}{}",
        if full { " --full" } else { "" }
    )
}
