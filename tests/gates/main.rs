//! Gates: checks on the code itself rather than on what it renders. The instruction-count gate
//! (`icount`: callgrind's counts of the hot kernels against committed baselines; its child
//! workloads are the `raywave-icount-child` binary, `icount_child.rs`) and the layering rule
//! (`layering`: only the lane layer names `wide`).

mod icount;
mod layering;
