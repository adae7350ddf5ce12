//! The parts of the `softraster` command line that tests and the binary
//! share: the tools that measure the renderer (`compare`, `accuracy`,
//! `bench`, `chart`, `report`) and the showcase scene's asset generator.
//! The renderer itself is the `softraster` library; it never imports this
//! package.

pub mod showcase;
pub mod tools;
