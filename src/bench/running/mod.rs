//! Running a bench: the sweep's points, the measured rounds that alternate the engines, and the
//! rounds of `--against --until-decided` judged at planned looks.

pub(crate) mod measure;
pub mod sequential;
pub mod sweep;
