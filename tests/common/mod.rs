#![allow(dead_code)]
pub mod compliant;
pub mod hertz;
pub mod leaning;
