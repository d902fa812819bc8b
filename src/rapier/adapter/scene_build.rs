//! From a [`Scene`] to a Rapier world with topple (or its native twin).

use crate::domino::RowSpec as DominoRow;
use std::collections::HashMap;

use super::backend::math::Real;
use super::backend::prelude::{
    ColliderBuilder, ColliderHandle, IntegrationParameters, PhysicsWorld, RigidBodyBuilder,
    RigidBodyHandle, Vector,
};
use super::ToppleRapier;
use crate::coupling::{ImpactReport, MaterialId};
use crate::input::InputError;
use crate::rapier::scene::{
    expand_row, pair_material, topple_settings, BodySpec, ImpactResponse, Scene, SceneError,
    SceneResult, ShapeKind, SolverSpec,
};

/// A vector of this build from f64 components.
fn vector(v: [f64; 2]) -> Vector {
    Vector::new(v[0] as Real, v[1] as Real)
}

/// A row's geometry, kept for the wave measures.
#[derive(Clone, Debug)]
pub struct RowInfo {
    /// The row as the domino layer sees it (parameters, spacing, n, push).
    pub spec: DominoRow,
    /// The blocks' colliders, in row order.
    pub colliders: Vec<ColliderHandle>,
}

/// A built scene, ready to step.
pub struct SceneWorld {
    /// The Rapier world.
    pub world: PhysicsWorld,
    /// topple (in native mode it only supplies per-pair materials).
    pub topple: ToppleRapier,
    /// Body names, handles and colliders in scene order (ground excluded).
    pub bodies: Vec<(String, RigidBodyHandle, ColliderHandle)>,
    /// The row, if the scene has one.
    pub row: Option<RowInfo>,
    /// Engine.
    pub engine: ImpactResponse,
    /// Simulated time (s).
    pub time: f64,
}

/// Builds the world of a scene for an engine.
///
/// ```
/// use topple::rapier::f64::build;
/// use topple::rapier::scene::{ImpactResponse, Scene};
/// let scene: Scene = toml::from_str(r#"
///     duration = 0.1
///     [row]
///     preset = "T"
///     n = 3
///     spacing = 0.35
/// "#).unwrap();
/// let mut sw = build(&scene, ImpactResponse::Topple).unwrap();
/// assert_eq!(sw.bodies.len(), 3);
/// sw.step();
/// assert!(sw.kinetic_energy() > 0.0); // block 1 is pushed
/// ```
pub fn build(scene: &Scene, engine: ImpactResponse) -> SceneResult<SceneWorld> {
    let mut scene = scene.clone();
    let row = match scene.row.clone() {
        Some(r) => Some(expand_row(&mut scene, &r)?),
        None => None,
    };
    let mut world = rapier_world(&scene, row.as_ref())?;
    let length_unit = f64::from(world.integration_parameters.length_unit);
    let mut topple = match engine {
        ImpactResponse::Topple => ToppleRapier::new(topple_settings(&scene.solver, length_unit)),
        ImpactResponse::Native => ToppleRapier::native(),
    };
    let ids = register_materials(&scene, &mut topple)?;
    let id = |name: &str| {
        ids.get(name)
            .copied()
            .ok_or_else(|| SceneError::invalid(format!("unknown material {name:?}")))
    };
    for p in &scene.pairs {
        topple.set_pair_material(
            id(&p.materials[0])?,
            id(&p.materials[1])?,
            pair_material(&p.law),
        );
    }
    if let Some(g) = &scene.ground {
        let m = id(&g.material)?;
        let (_, c) = world.insert(
            RigidBodyBuilder::fixed().translation(vector([0.0, g.y - 1.0])),
            ColliderBuilder::cuboid(1.0e3, 1.0),
        );
        topple.manage(&mut world.colliders, c, m);
    }
    let mut bodies = Vec::with_capacity(scene.bodies.len());
    for (i, b) in scene.bodies.iter().enumerate() {
        let name = b.name.clone().unwrap_or_else(|| i.to_string());
        let (h, c) = world.insert(rigid_body(b), collider(b, &name)?);
        topple.manage(&mut world.colliders, c, id(&b.material)?);
        bodies.push((name, h, c));
    }
    let row = row.map(|spec| RowInfo {
        spec,
        colliders: bodies.iter().map(|b| b.2).collect(),
    });
    Ok(SceneWorld {
        world,
        topple,
        bodies,
        row,
        engine,
        time: 0.0,
    })
}

/// An empty Rapier world with the scene's gravity and solver settings: the
/// length unit and contact stiffness default to a row's (its block height,
/// [`crate::rapier::ROW_CONTACT_HERTZ`]) for a scene with a row.
fn rapier_world(scene: &Scene, row: Option<&DominoRow>) -> SceneResult<PhysicsWorld> {
    let s = &scene.solver;
    let length_unit = s
        .length_unit
        .unwrap_or(row.map_or(1.0, |spec| spec.params.block.height));
    let positive = |field: &str, x: f64, allowed: &str| {
        if x > 0.0 && x.is_finite() {
            Ok(())
        } else {
            Err(InputError::new(field, x, allowed))
        }
    };
    positive("solver.dt", s.dt, "0 < solver.dt, finite (s)")?;
    positive(
        "solver.length_unit",
        length_unit,
        "0 < solver.length_unit, finite (m)",
    )?;
    if scene.duration.is_nan() || scene.duration < 0.0 {
        return Err(InputError::new("duration", scene.duration, "0 ≤ duration (s)").into());
    }
    if let Some(f) = s.contact_hertz {
        positive(
            "solver.contact_hertz",
            f,
            "0 < solver.contact_hertz, finite (Hz)",
        )?;
    }
    let hertz = s
        .contact_hertz
        .or(row.map(|_| crate::rapier::ROW_CONTACT_HERTZ));
    Ok(PhysicsWorld {
        gravity: vector(scene.gravity),
        integration_parameters: integration_parameters(s, length_unit, hertz),
        ..PhysicsWorld::default()
    })
}

/// Rapier's parameters for a scene's solver section: its step `dt` (s), the
/// length unit (m; Rapier scales its tolerances by it) and, when given, the
/// natural frequency of soft contacts (Hz; fixed pairs get twice the value,
/// [`crate::rapier::ROW_CONTACT_HERTZ`] for rows). The one definition used by
/// the scene worlds and by the Bevy plugin's rows.
///
/// ```
/// use topple::rapier::f64::integration_parameters;
/// use topple::rapier::scene::SolverSpec;
/// let p = integration_parameters(&SolverSpec::default(), 0.08, Some(480.0));
/// assert_eq!(p.length_unit, 0.08);
/// assert_eq!(p.contact_softness.natural_frequency, 480.0);
/// ```
pub fn integration_parameters(
    s: &SolverSpec,
    length_unit: f64,
    contact_hertz: Option<f64>,
) -> IntegrationParameters {
    let mut p = IntegrationParameters {
        dt: s.dt as Real,
        length_unit: length_unit as Real,
        num_solver_iterations: s.iterations.max(1),
        contact_recycling: s.contact_recycling,
        ..IntegrationParameters::default()
    };
    if let Some(f) = contact_hertz {
        p.contact_softness.natural_frequency = f as Real;
        p.static_contact_softness.natural_frequency = (2.0 * f) as Real;
    }
    p
}

/// Adds the scene's materials to topple; returns their ids by name.
fn register_materials(
    scene: &Scene,
    topple: &mut ToppleRapier,
) -> SceneResult<HashMap<String, MaterialId>> {
    let mut ids = HashMap::new();
    for m in &scene.materials {
        if !(0.0..=1.0).contains(&m.restitution) || m.stiffness <= 0.0 || m.friction < 0.0 {
            return Err(SceneError::invalid(format!(
                "material {:?}: need stiffness > 0, restitution in [0, 1], friction >= 0",
                m.name
            )));
        }
        let law = m.law();
        if ids
            .insert(m.name.clone(), topple.add_material(pair_material(&law)))
            .is_some()
        {
            return Err(SceneError::invalid(format!(
                "material {:?} defined twice",
                m.name
            )));
        }
    }
    Ok(ids)
}

/// The rigid body of a scene body: fixed or dynamic, at its pose and velocity.
fn rigid_body(b: &BodySpec) -> RigidBodyBuilder {
    let builder = if b.fixed {
        RigidBodyBuilder::fixed()
    } else {
        RigidBodyBuilder::dynamic()
    };
    builder
        .translation(vector(b.position))
        .rotation(b.angle as Real)
        .linvel(vector(b.velocity))
        .angvel(b.angular_velocity as Real)
}

/// The collider of a scene body: its shape with its mass or density
/// (1000 kg/m² by default).
fn collider(b: &BodySpec, name: &str) -> SceneResult<ColliderBuilder> {
    let collider = match b.shape {
        ShapeKind::Box => {
            let [w, h] = b
                .size
                .ok_or_else(|| SceneError::invalid(format!("body {name}: a box needs size")))?;
            ColliderBuilder::cuboid((0.5 * w) as Real, (0.5 * h) as Real)
        }
        ShapeKind::Ball => {
            let r = b
                .radius
                .ok_or_else(|| SceneError::invalid(format!("body {name}: a ball needs radius")))?;
            ColliderBuilder::ball(r as Real)
        }
    };
    Ok(match (b.mass, b.density) {
        (Some(mass), _) => collider.mass(mass as Real),
        (None, d) => collider.density(d.unwrap_or(1000.0) as Real),
    })
}

impl SceneWorld {
    /// One time step; returns the impacts topple resolved in it.
    pub fn step(&mut self) -> &[ImpactReport] {
        self.topple.step(&mut self.world);
        self.time += f64::from(self.world.integration_parameters.dt);
        self.topple.last_impacts()
    }

    /// Kinetic energy of all bodies (J per unit depth).
    pub fn kinetic_energy(&self) -> f64 {
        self.bodies
            .iter()
            .map(|b| f64::from(self.world.bodies[b.1].kinetic_energy()))
            .sum()
    }
}
