//! The figures of a study, pure functions of images and rows: errors against the converged
//! reference, the fits across budgets and samplers, the error's spectrum, what the eye sees of
//! it, and the penumbra mask the regions come from.

pub mod errors;
pub mod fits;
pub mod mask;
pub mod perceived;
pub mod spectrum;
