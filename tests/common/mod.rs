#![allow(dead_code)]

pub mod cooperative;
pub mod hertz;
