//! The coupling layer: what every engine needs around the LZB resolver,
//! engine-agnostic. Plain `f64` data in, post-impact velocities out; the
//! reference engine and every Rapier adapter (f64 and f32) use it.
//!
//! | item | file | role |
//! | --- | --- | --- |
//! | [`MaterialId`], [`PairMaterial`], [`MaterialTable`] | `material.rs` | impact law per body material; pair rules override (Table 1's domino–domino and domino–ground) |
//! | [`ManifoldPoint`], [`PatchRule`], [`for_each_contact_point`] | `patch.rs` | λ points across a flat contact patch (paper Eq. 10, docs/model.md §5) |
//! | [`PointContact`], [`ImpactGroups`], [`ImpactReport`], [`ContactRecord`] | `group.rs` | which contacts start an impact, the bodies that take part, one solve per group |
//! | [`FallbackPolicy`], [`GroupSolver`], [`Resolution`] | `fallback.rs` | an impact that cannot finish: held e = 0 retry, then plastic; counted |
//! | [`PlasticSolver`] | `plastic/` | the plastic impact with Coulomb friction (the last stage): sweeps, then a direct LCP solve |
//! | [`ToppleSettings`] | `settings.rs` | the settings of an impact pass |
//!
//! ```
//! use topple::coupling::{ImpactGroups, PointContact, Resolution, ToppleSettings};
//! use topple::impact::{Body, ContactMaterial};
//! // a ball falls flat onto the ground at 2 m/s, e = 0.5: it leaves at 1 m/s
//! let mut bodies = [Body::new(1.0, 0.004).with_position([0.0, 0.1]).with_velocity([0.0, -2.0])];
//! let ground = PointContact {
//!     bodies: [None, Some(0)], point: [0.0, 0.0], normal: [0.0, 1.0], dist: 0.0,
//!     material: ContactMaterial::hertz(1e8).with_restitution(0.5), persistent: false,
//! };
//! let mut groups = ImpactGroups::default();
//! groups.resolve(&mut bodies, &[ground], &ToppleSettings::default());
//! assert_eq!(groups.reports()[0].resolution, Resolution::Lzb);
//! assert!((bodies[0].velocity[1] - 1.0).abs() < 1e-4);
//! ```

mod fallback;
mod group;
mod material;
mod patch;
mod plastic;
mod settings;

pub use fallback::{gains_energy, FallbackPolicy, GroupSolver, LargeGroup, Resolution};
pub use group::{
    normal_velocity, seed_approach, ContactRecord, ImpactGroups, ImpactReport, PointContact,
};
pub use material::{MaterialId, MaterialTable, PairMaterial};
pub use patch::{for_each_contact_point, ManifoldPoint, PatchRule};
pub use plastic::PlasticSolver;
pub use settings::ToppleSettings;
