//! A minimal domino-row generator (Table 1 presets of the paper) and the
//! wave measures of Sec. 3.1: hit times and v̂_i = (s + d)/(t_i √(gh)).

use super::format::{
    BodySpec, GroundSpec, MaterialSpec, PairLaw, PairSpec, RowSpec, Scene, ShapeKind,
};

/// Geometry and contact parameters of one Table 1 preset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preset {
    /// Height h (m).
    pub height: f64,
    /// Thickness d (m).
    pub thickness: f64,
    /// Domino–domino μ₁, μ₁ˢ, e₁, k₁ (N/m^1.5).
    pub block: [f64; 4],
    /// Domino–ground μ₂, μ₂ˢ, e₂, k₂ (N/m^1.5).
    pub ground: [f64; 4],
}

/// Table 1 of the paper (Domino X, T, P); `None` for an unknown name.
///
/// ```
/// let t = topple::rapier::scene::preset("T").unwrap();
/// assert_eq!((t.height, t.thickness), (0.08, 0.0096));
/// ```
pub fn preset(name: &str) -> Option<Preset> {
    let (h, d, block, ground) = match name.to_ascii_uppercase().as_str() {
        "X" => (4.18e-2, 7.58e-3, [0.17, 0.20, 0.85], [0.25, 0.30, 0.50]),
        "T" => (8.00e-2, 9.60e-3, [0.15, 0.18, 0.62], [0.20, 0.25, 0.50]),
        "P" => (8.00e-2, 9.90e-3, [0.25, 0.30, 0.55], [0.30, 0.36, 0.50]),
        _ => return None,
    };
    Some(Preset {
        height: h,
        thickness: d,
        block: [block[0], block[1], block[2], 2.3e8],
        ground: [ground[0], ground[1], ground[2], 6.9e8],
    })
}

/// Adds the row's materials ("block", "ground"), pair rules, ground and
/// blocks ("block1" …) to a scene; returns the preset with the overrides
/// applied. Blocks stand on the ground at y = 0,
/// block i (from 1) centred at x = (i − 1)(s + d); block 1 rotates clockwise
/// about its front bottom edge at θ̇ = push/t̄.
pub fn expand_row(scene: &mut Scene, row: &RowSpec) -> anyhow::Result<Preset> {
    let mut p = preset(&row.preset)
        .ok_or_else(|| anyhow::anyhow!("unknown domino preset {:?} (X, T or P)", row.preset))?;
    let [mut mu1, mut mus1, mut e1, mut k1] = p.block;
    let [mut mu2, mut mus2, mut e2, mut k2] = p.ground;
    if row.ideal {
        (mu1, mus1, e1) = (0.0, 0.0, 0.0);
        (mu2, mus2, e2) = (0.9, 0.9, 0.0);
    }
    let o = &row.overrides;
    let set = |x: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *x = v;
        }
    };
    set(&mut p.height, o.height);
    set(&mut p.thickness, o.thickness);
    set(&mut mu1, o.mu1);
    set(&mut mus1, o.mu1_stick.or(o.mu1));
    set(&mut e1, o.e1);
    set(&mut k1, o.k1);
    set(&mut mu2, o.mu2);
    set(&mut mus2, o.mu2_stick.or(o.mu2));
    set(&mut e2, o.e2);
    set(&mut k2, o.k2);
    p.block = [mu1, mus1, e1, k1];
    p.ground = [mu2, mus2, e2, k2];
    let alpha = o.alpha.unwrap_or(1.5);
    let factor = o.impact_friction_factor.unwrap_or(0.5);
    let law = |mu, mus, e, k| PairLaw {
        stiffness: k,
        exponent: alpha,
        restitution: e,
        friction: mu,
        stick_friction: mus,
        impact_friction_factor: factor,
    };
    let block = law(mu1, mus1, e1, k1);
    let ground = law(mu2, mus2, e2, k2);
    let material = |name: &str, l: &PairLaw| MaterialSpec {
        name: name.into(),
        stiffness: l.stiffness,
        exponent: l.exponent,
        restitution: l.restitution,
        friction: l.friction,
        stick_friction: l.stick_friction,
        impact_friction_factor: l.impact_friction_factor,
    };
    scene.materials.push(material("block", &block));
    scene.materials.push(material("ground", &ground));
    scene.pairs.push(PairSpec {
        materials: ["block".into(), "block".into()],
        law: block,
    });
    scene.pairs.push(PairSpec {
        materials: ["block".into(), "ground".into()],
        law: ground,
    });
    scene.ground = Some(GroundSpec {
        y: 0.0,
        material: "ground".into(),
    });
    let (h, d) = (p.height, p.thickness);
    let g = scene.gravity[0].hypot(scene.gravity[1]);
    let omega = -row.push / (h / g).sqrt(); // clockwise: topples towards +x
    for i in 0..row.n {
        let x = i as f64 * (row.spacing * h + d);
        let (velocity, angular_velocity) = if i == 0 {
            // v = ω × (c − pivot), pivot at the front bottom edge.
            let r = [-0.5 * d, 0.5 * h];
            ([-omega * r[1], omega * r[0]], omega)
        } else {
            ([0.0, 0.0], 0.0)
        };
        scene.bodies.push(BodySpec {
            name: Some(format!("block{}", i + 1)),
            shape: ShapeKind::Box,
            size: Some([d, h]),
            radius: None,
            position: [x, 0.5 * h],
            angle: 0.0,
            velocity,
            angular_velocity,
            density: Some(row.density),
            mass: row.mass,
            fixed: false,
            material: "block".into(),
        });
    }
    Ok(p)
}

/// The wave measures of a row: hit times and dimensionless speeds.
///
/// ```
/// use topple::rapier::scene::RowMeasures;
/// // 10 blocks, one pitch (s + d = 0.1 m) every 0.05 s, h = 0.1 m, g = 10
/// let hits: Vec<f64> = (0..10).map(|i| 0.05 * i as f64).collect();
/// let m = RowMeasures::from_hit_times(hits, 10, 0.09, 0.01, 0.1, 10.0);
/// assert!((m.natural_speed.unwrap() - 2.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct RowMeasures {
    /// T_i: time block i − 1 hit block i (s); T_1 = 0 (block 1 is pushed).
    pub hit_times: Vec<f64>,
    /// v̂_i = (s + d)/(t_i √(gh)), t_i = T_{i+1} − T_i, for every block i that hit
    /// its successor.
    pub speeds: Vec<f64>,
    /// Mean v̂_i over blocks 7 ..= n − 2 (the paper's natural speed, the last
    /// block excluded as in rapier-notes), if the wave got there.
    pub natural_speed: Option<f64>,
    /// Standard deviation of those v̂_i.
    pub natural_speed_spread: Option<f64>,
}

impl RowMeasures {
    /// Measures from hit times, for a row of `n` blocks of height `h` and
    /// thickness `d` at spacing `s` (all m), gravity `g` (m/s²).
    pub fn from_hit_times(hit_times: Vec<f64>, n: usize, s: f64, d: f64, h: f64, g: f64) -> Self {
        let vbar = (g * h).sqrt();
        let speeds: Vec<f64> = hit_times
            .windows(2)
            .map(|w| (s + d) / ((w[1] - w[0]) * vbar))
            .collect();
        // blocks 7 ..= n − 2 are speeds[6 .. n − 2]
        let hi = n.saturating_sub(2).min(speeds.len());
        let (natural_speed, natural_speed_spread) = if hi > 6 && speeds.len() >= n - 1 {
            let v = &speeds[6..hi];
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64;
            (Some(mean), Some(var.sqrt()))
        } else {
            (None, None)
        };
        RowMeasures {
            hit_times,
            speeds,
            natural_speed,
            natural_speed_spread,
        }
    }
}
