//! The tools that measure the renderer, behind the default `tools` feature
//! (they bring clap, plotters, dejavu and nv-flip, a C++ build): `compare`
//! (golden-frame metrics), `accuracy` (error tables against references),
//! `bench` (the reference turntables) and `chart` (time against error per
//! method). The renderer itself never imports them.

pub mod accuracy;
pub mod bench;
pub mod chart;
pub mod compare;
pub mod report;
