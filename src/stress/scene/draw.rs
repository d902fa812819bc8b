//! The seeded draw of one random scene: piles, stacks and pyramids of the
//! shapes the plugin supports, random sizes and masses, in any length unit
//! from metres to pixels, at any time step from 1/240 to 1/30 s.

use super::super::combo::SplitMix64;
use crate::coupling::ToppleSettings;
use crate::rapier::scene::{
    BodySpec, GroundSpec, ImpactResponse, MaterialSpec, Scene, ShapeKind, SolverSpec, WorkBudget,
};
use crate::rapier::Precision;

/// A shape the scenes draw. Each is built from one size (m) by
/// `StressShape::body`; a shape the plugin gains is one more variant there
/// and one more entry in [`SHAPES`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StressShape {
    /// A box, aspect ratio 1:3 to 3:1.
    Box,
    /// A ball.
    Ball,
}

/// The shapes this build's scene format supports (`ShapeKind`), in the
/// order they are drawn. Capsules, convex polygons, round and compound
/// shapes join here as the scene format gains them.
pub const SHAPES: &[StressShape] = &[StressShape::Box, StressShape::Ball];

impl StressShape {
    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            StressShape::Box => "box",
            StressShape::Ball => "ball",
        }
    }

    /// A body of this shape about `size` across (m), its aspect drawn from
    /// `g`; `None` if the scene format cannot hold it.
    fn body(self, size: f64, g: &mut SplitMix64) -> Option<BodySpec> {
        let mut b = blank();
        match self {
            StressShape::Box => {
                let aspect = 3f64.powf(g.range(-1.0, 1.0));
                b.size = Some([size * aspect.sqrt(), size / aspect.sqrt()]);
            }
            StressShape::Ball => {
                b.shape = ShapeKind::Ball;
                b.radius = Some(0.5 * size);
            }
        }
        Some(b)
    }
}

/// A box at the origin, at rest, without size, mass or material.
fn blank() -> BodySpec {
    BodySpec {
        name: None,
        shape: ShapeKind::Box,
        size: None,
        radius: None,
        position: [0.0, 0.0],
        angle: 0.0,
        velocity: [0.0, 0.0],
        angular_velocity: 0.0,
        density: None,
        mass: None,
        fixed: false,
        material: String::new(),
    }
}

/// A box of `w` × `h` (m) centred at `position`.
fn box_at(w: f64, h: f64, position: [f64; 2]) -> BodySpec {
    let mut body = blank();
    body.size = Some([w, h]);
    body.position = position;
    body
}

/// What a scene is built as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// Bodies of every supported shape dropped in layers into a bin.
    Pile,
    /// Boxes stacked one on another, a body dropped on top.
    Stack,
    /// A pyramid of boxes, struck by a thrown body.
    Pyramid,
}

impl SceneKind {
    /// Every kind, in the order they are drawn.
    pub const ALL: [SceneKind; 3] = [SceneKind::Pile, SceneKind::Stack, SceneKind::Pyramid];

    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Pile => "pile",
            SceneKind::Stack => "stack",
            SceneKind::Pyramid => "pyramid",
        }
    }
}

/// Who runs a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SceneEngine {
    /// Rapier f64 with topple's impacts.
    RapierF64,
    /// Rapier f32 (bevy_rapier2d's build) with topple's impacts.
    RapierF32,
    /// Rapier alone, either build: the baseline.
    Native,
}

impl SceneEngine {
    /// Every engine, in turn.
    pub const ALL: [SceneEngine; 3] = [
        SceneEngine::RapierF64,
        SceneEngine::RapierF32,
        SceneEngine::Native,
    ];

    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            SceneEngine::RapierF64 => "rapier-f64",
            SceneEngine::RapierF32 => "rapier-f32",
            SceneEngine::Native => "native",
        }
    }

    /// Native Rapier is the baseline: its violations are printed, not
    /// counted.
    pub fn is_baseline(self) -> bool {
        self == SceneEngine::Native
    }
}

/// One drawn scene with how it runs.
#[derive(Clone, Debug)]
pub struct SceneCombo {
    /// Index in the sweep (with the seed, it reproduces the scene).
    pub index: usize,
    /// What it is built as.
    pub kind: SceneKind,
    /// Who runs it.
    pub engine: SceneEngine,
    /// The Rapier build.
    pub precision: Precision,
    /// Length units per metre (1: metres, 100: pixels at 100 px/m).
    pub unit: f64,
    /// The scene, in its length unit (gravity, sizes, speeds scaled).
    pub scene: Scene,
}

impl SceneCombo {
    /// The topple engine of this combination (native for the baseline).
    pub fn rapier_engine(&self) -> ImpactResponse {
        match self.engine {
            SceneEngine::Native => ImpactResponse::Native,
            _ => ImpactResponse::Topple,
        }
    }

    /// The scene as TOML (what `topple scene FILE` runs).
    #[cfg(feature = "scene-files")]
    pub fn toml(&self) -> String {
        toml::to_string(&self.scene).unwrap_or_else(|e| format!("# not serialisable: {e}"))
    }
}

/// Draws scene `index` of the sweep with `seed`, with `n_lo..=n_hi` bodies
/// and `duration` seconds of simulated time.
pub fn draw_scene(seed: u64, index: usize, n_lo: usize, n_hi: usize, duration: f64) -> SceneCombo {
    let mut g = SplitMix64::new(seed ^ (index as u64).wrapping_mul(0x9FB2_1C65_1E98_DF25));
    g.next_u64();
    // stratified, so that any 36 consecutive scenes hold every engine,
    // kind, half of the unit range and half of the time-step range
    // together: engine fastest, then kind, unit half, dt half
    let engine = SceneEngine::ALL[index % 3];
    let kind = SceneKind::ALL[(index / 3) % 3];
    let (unit_half, dt_half) = (((index / 9) % 2) as f64, ((index / 18) % 2) as f64);
    let precision = match engine {
        SceneEngine::RapierF64 => Precision::F64,
        SceneEngine::RapierF32 => Precision::F32,
        // with the kind, (index / 3) % 6: every kind in both builds
        SceneEngine::Native => [Precision::F64, Precision::F32][(index / 3) % 2],
    };
    // metres to pixels at 100 px/m, log-uniform within its half (1 to 10
    // or 10 to 100 units per metre)
    let unit = 10f64.powf(unit_half + g.range(0.0, 1.0));
    // 1/240 s to 1/30 s, log-uniform within its half (1/240 to 1/85 s or
    // 1/85 to 1/30 s)
    let dt = 8f64.powf(0.5 * (dt_half + g.range(0.0, 1.0))) / 240.0;
    let n = n_lo + (g.next_u64() % (n_hi - n_lo + 1) as u64) as usize;
    let materials = draw_materials(&mut g);
    let names: Vec<String> = materials.iter().map(|m| m.name.clone()).collect();
    let base = 10f64.powf(g.range(-1.3, -0.3)); // 5 cm to 50 cm
    let mut placed = match kind {
        SceneKind::Pile => pile(&mut g, n, base),
        SceneKind::Stack => stack(&mut g, n, base),
        SceneKind::Pyramid => pyramid(&mut g, n, base),
    };
    for b in placed.iter_mut() {
        if !b.fixed {
            // masses 10⁻² to 10² kg, log-uniform, each body its own
            b.mass = Some(10f64.powf(g.range(-2.0, 2.0)));
        }
        b.material = names[1 + (g.next_u64() % (names.len() - 1) as u64) as usize].clone();
    }
    // scale lengths into the unit: positions, sizes, speeds, gravity;
    // stiffness k (N/m^α) becomes k U^(1−α) in kg·unit/s² per unit^α
    let scale = |v: [f64; 2]| [v[0] * unit, v[1] * unit];
    let bodies = placed
        .into_iter()
        .enumerate()
        .map(|(i, mut b)| {
            b.name = Some(format!("b{}", i + 1));
            b.position = scale(b.position);
            b.velocity = scale(b.velocity);
            b.size = b.size.map(scale);
            b.radius = b.radius.map(|r| r * unit);
            b
        })
        .collect();
    let materials = materials
        .into_iter()
        .map(|mut m| {
            m.stiffness *= unit.powf(1.0 - m.exponent);
            m
        })
        .collect();
    let scene = Scene {
        description: format!(
            "stress scene {index}: {} of {n} bodies, {:.3} units per metre, dt 1/{:.0} s",
            kind.name(),
            unit,
            1.0 / dt
        ),
        duration,
        gravity: [0.0, -9.81 * unit],
        solver: SolverSpec {
            dt,
            // what a game sets: its length unit (bevy_rapier's
            // pixels_per_meter); everything else at the defaults
            length_unit: Some(unit * base),
            // a game's frame budget: the impacts of one step share the
            // work the Bevy plugin gives a step by default
            max_work: WorkBudget::Work(ToppleSettings::DEFAULT_STEP_WORK),
            ..SolverSpec::default()
        },
        materials,
        pairs: Vec::new(),
        ground: Some(GroundSpec {
            y: 0.0,
            material: names[0].clone(),
        }),
        bodies,
        row: None,
    };
    SceneCombo {
        index,
        kind,
        engine,
        precision,
        unit,
        scene,
    }
}

/// The ground's material and two or three body materials: restitution from
/// plastic to elastic, friction 0 to 0.8, stiffness 10⁶ to 10¹⁰ N/m^1.5.
fn draw_materials(g: &mut SplitMix64) -> Vec<MaterialSpec> {
    let count = 3 + (g.next_u64() % 2) as usize;
    (0..count)
        .map(|k| {
            let friction = g.range(0.0, 0.8);
            MaterialSpec {
                name: if k == 0 {
                    "ground".into()
                } else {
                    format!("m{k}")
                },
                stiffness: 10f64.powf(g.range(6.0, 10.0)),
                exponent: 1.5,
                restitution: g.pick(&[0.0, 0.3, 0.6, 0.9, 1.0]),
                friction,
                stick_friction: friction * g.range(1.0, 1.2),
                impact_friction_factor: 1.0,
            }
        })
        .collect()
}

/// A body of a drawn shape about `size` across at `position`.
fn body_at(g: &mut SplitMix64, size: f64, position: [f64; 2]) -> BodySpec {
    let mut shapes = SHAPES.to_vec();
    let mut body = None;
    while body.is_none() && !shapes.is_empty() {
        let k = (g.next_u64() % shapes.len() as u64) as usize;
        body = shapes.remove(k).body(size, g);
    }
    let mut body = body.expect("the box is always supported");
    body.position = position;
    body
}

/// A fixed wall (a box) of the bin.
fn wall(centre: [f64; 2], half: [f64; 2]) -> BodySpec {
    let mut b = box_at(2.0 * half[0], 2.0 * half[1], centre);
    b.fixed = true;
    b
}

/// Bodies in a grid of cells above a bin, each turned and thrown a little:
/// they fall in layers and pile up.
fn pile(g: &mut SplitMix64, n: usize, base: f64) -> Vec<BodySpec> {
    let cols = ((n as f64).sqrt().ceil() as usize).max(2);
    let cell = 2.0 * base;
    let width = cols as f64 * cell;
    let mut out = vec![
        wall([-0.5 * base, 2.0 * width], [0.5 * base, 2.0 * width]),
        wall([width + 0.5 * base, 2.0 * width], [0.5 * base, 2.0 * width]),
    ];
    let drop = g.range(0.0, 2.0) * base;
    for k in 0..n {
        let (c, r) = (k % cols, k / cols);
        let size = base * g.range(0.4, 1.0);
        let centre = [(c as f64 + 0.5) * cell, drop + (r as f64 + 0.5) * cell];
        let mut b = body_at(g, size, centre);
        b.angle = g.range(-3.2, 3.2);
        b.velocity = [g.range(-0.5, 0.5), g.range(-1.0, 0.5)];
        b.angular_velocity = g.range(-3.0, 3.0);
        out.push(b);
    }
    out
}

/// Boxes stacked one on another (each a little off centre, a hair above the
/// one below), and a body dropped onto the top.
fn stack(g: &mut SplitMix64, n: usize, base: f64) -> Vec<BodySpec> {
    let mut out = Vec::with_capacity(n);
    let mut y = 0.0;
    for _ in 0..n.saturating_sub(1).max(1) {
        let w = base * g.range(0.6, 1.4);
        let h = base * g.range(0.3, 1.0);
        let gap = g.range(0.0, 0.02) * h;
        let x = g.range(-0.1, 0.1) * w;
        out.push(box_at(w, h, [x, y + gap + 0.5 * h]));
        y += gap + h;
    }
    if n > 1 {
        let size = base * g.range(0.3, 1.0);
        let drop = g.range(0.0, 2.0) * base;
        let x = g.range(-0.3, 0.3) * base;
        let mut b = body_at(g, size, [x, y + drop + size]);
        b.velocity = [0.0, -g.range(0.0, 3.0)];
        out.push(b);
    }
    out
}

/// A pyramid of equal boxes, rows a hair apart, and a body thrown at it.
fn pyramid(g: &mut SplitMix64, n: usize, base: f64) -> Vec<BodySpec> {
    let mut rows = 1;
    while (rows + 1) * (rows + 2) / 2 < n {
        rows += 1;
    }
    let (w, h) = (base, base * g.range(0.5, 1.0));
    let spacing = w * g.range(1.0, 1.2);
    let mut out = Vec::new();
    let mut y = 0.0;
    for r in 0..rows {
        let count = rows - r;
        let gap = g.range(0.0, 0.01) * h;
        for c in 0..count {
            let x = (c as f64 + 0.5 * r as f64) * spacing;
            out.push(box_at(w, h, [x, y + gap + 0.5 * h]));
        }
        y += gap + h;
    }
    let size = base * g.range(0.3, 1.0);
    let mut b = body_at(g, size, [-3.0 * base, 0.5 * y + size]);
    let speed = g.range(0.0, 5.0);
    b.velocity = [speed, g.range(0.0, 1.0) * speed];
    b.angular_velocity = g.range(-5.0, 5.0);
    out.push(b);
    out
}
