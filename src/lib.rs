//! # topple
//!
//! Physically right multiple impacts for 2D rigid bodies: the energetic
//! multiple-impact model of Liu, Zhao and Brogliato (the "LZB model") with the
//! λ-point line contact and Coulomb friction of Shi, Liu, Wang and Liu,
//! *Toppling dynamics of regularly spaced dominoes in an array*.
//!
//! | layer | what it holds |
//! | --- | --- |
//! | [`impact`] | the LZB resolver: bodies + contacts in, post-impact velocities out |
//! | [`domino`] | block geometry, Table 1 presets, row builder, wave-speed measures |
//! | [`theory`] | cooperative, extended and single-collision models of the wave |
//! | [`reference`] | the paper's reduced-coordinate domino model (the accuracy oracle) |
//! | [`rapier`] | the plugin for `rapier2d-f64` |
//!
//! Data flows down the table: a module uses the ones above it, never one below.

pub mod domino;
pub mod impact;
pub mod rapier;
pub mod reference;
pub mod theory;
