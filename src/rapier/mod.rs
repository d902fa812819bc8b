//! The plugin for rapier2d-f64: LZB impacts and λ-point contact inside a
//! Rapier world.
//!
//! | item | role | engine |
//! | --- | --- | --- |
//! | [`MaterialTable`], [`PairMaterial`] | impact law per collider, pair overrides | agnostic |
//! | [`for_each_contact_point`], [`PatchRule`] | λ points across flat contact patches | agnostic |
//! | [`ImpactGroups`], [`PointContact`], [`ToppleSettings`] | impact events, their groups, the resolver call | agnostic |
//! | [`ToppleRapier`], [`ToppleHooks`] | thin adapter and physics hook for rapier2d-f64 | Rapier |
//! | [`scene`] | TOML scenes (boxes, balls, domino rows) run with or without topple | Rapier |
//!
//! After each Rapier step the narrow phase describes the start of that step;
//! topple queries parry2d-f64 on Rapier's candidate pairs for the contacts at
//! the current positions, turns flat patches into λ points, finds closed
//! contacts that approach, groups the bodies connected through closed
//! contacts, and resolves each group with [`crate::impact::ImpactSolver`].
//! On managed pairs the hook switches Rapier's restitution off and drops its
//! speculative (still open) contact points, which would otherwise stop an
//! approaching pair inelastically at the instant of touching.

pub mod chain;
mod group;
mod hooks;
mod material;
mod patch;
pub mod scene;
mod world;

pub use group::{normal_velocity, ImpactGroups, ImpactReport, PointContact, ToppleSettings};
pub use hooks::{HookMode, ToppleHooks};
pub use material::{MaterialId, MaterialTable, PairMaterial};
pub use patch::{for_each_contact_point, ManifoldPoint, PatchRule};
pub use world::{ToppleRapier, ToppleStats};
