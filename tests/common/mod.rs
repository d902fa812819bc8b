pub mod hertz;
