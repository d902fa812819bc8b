//! # topple
//!
//! Physically right multiple impacts for 2D rigid bodies: the energetic
//! multiple-impact model of Liu, Zhao and Brogliato (the "LZB model") with the
//! λ-point line contact and Coulomb friction of Shi, Liu, Wang and Liu,
//! *Toppling dynamics of regularly spaced dominoes in an array*.
//!
//! | layer | what it holds |
//! | --- | --- |
//! | [`input`] | the structured error of a bad value: field, value and allowed range |
//! | [`atomic`] | files written whole or not at all (temporary name, then rename) |
//! | [`impact`] | the LZB resolver: bodies + contacts in, post-impact velocities out |
//! | [`coupling`] | engine-agnostic: materials, λ-point patches, impact groups, the fallback policy |
//! | [`domino`] | block geometry, Table 1 presets, row builder, wave-speed measures |
//! | [`theory`] | cooperative, extended and single-collision models of the wave |
//! | [`validate`] | input checks at the entry points: field, value and allowed range on one line |
//! | [`reference`](mod@reference) | the paper's reduced-coordinate domino model (the accuracy oracle) |
//! | [`rapier`] | the plugin for Rapier, one source for `rapier2d-f64` and `rapier2d` (f32) |
//! | [`engines`] | one interface ([`engines::RowEngine`]) for every engine that runs a domino row |
//! | [`stress`] | the stress sweep: seeded combinations over every engine, invariants checked independently |
//!
//! Data flows down the table: a module uses the ones above it, never one below
//! (the Bevy plugin, `topple::bevy` with the `bevy` feature, sits on all of
//! them; `tests/module_graph.rs` checks the order and that no files import
//! each other in a cycle).
//!
//! Cargo features: `f64` and `f32` compile the two Rapier builds
//! (`rapier::f64`, `rapier::f32`), `parallel` runs the sweeps and a Rapier
//! step's independent impacts on rayon, `bevy` adds the Bevy plugin with the
//! f32 build only (and `parallel`), `cli` the `topple`
//! command; the defaults are `cli`, `f32`, `f64` and `parallel`.
//! The Rapier crates topple is built against are re-exported, so a user does
//! not have to spell their pre-release versions: [`rapier2d_f64`] and
//! [`rapier2d`].

// `rapier::f64` and `rapier::f32` compile the same adapter files (one source,
// two precisions, as Rapier builds rapier2d and rapier2d-f64).
#![allow(clippy::duplicate_mod)]
#![warn(missing_docs)]
#![cfg_attr(docsrs, feature(doc_cfg))]
// The docs link to both Rapier builds and to the sweeps; a build that
// leaves one of them out (e.g. a game's `bevy` alone, f32 only) keeps those
// links as text. With every feature (what docs.rs builds) they are checked.
#![cfg_attr(
    not(all(feature = "f32", feature = "f64")),
    allow(rustdoc::broken_intra_doc_links)
)]

pub mod atomic;
#[cfg(feature = "bevy")]
pub mod bevy;
mod clock;
pub mod coupling;
pub mod domino;
pub mod engines;
pub mod impact;
pub mod input;
mod par;
pub mod rapier;
pub mod reference;
#[cfg(all(feature = "f32", feature = "f64"))]
pub mod stress;
pub mod theory;
pub mod validate;

#[cfg(feature = "f32")]
pub use rapier2d;
#[cfg(feature = "f64")]
pub use rapier2d_f64;

// The README's code blocks compile and run as doctests, so they cannot go stale.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
