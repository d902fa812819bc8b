#![allow(dead_code)]
pub mod compliant;
pub mod cooperative;
pub mod hertz;
pub mod leaning;
