//! Scenes (placeholder).
