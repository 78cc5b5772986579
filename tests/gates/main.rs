//! Gates: checks on the code itself rather than on what it renders. The instruction-count gate
//! (`icount`: callgrind's counts of the hot kernels against committed baselines; its child
//! workloads are the `raywave-icount-child` binary, `icount_child.rs`), the layering rule
//! (`layering`: only the lane layer names `wide`), the module map (`module_map`:
//! docs/ARCHITECTURE.md's tree is `src/`), the docs' budgets (`doc_budgets`: README.md,
//! docs/PERFORMANCE.md and docs/BENCHMARKING.md within their line counts, docs/TESTING.md
//! without a diary of CI timings), the build's reuse (`build_reuse`: `cargo test` compiles no
//! dependency again that `cargo run` compiled) and the mutant check's patches (`mutants_apply`:
//! every `tests/mutants/*.patch` still applies to `src/`).

mod build_reuse;
mod doc_budgets;
mod icount;
mod layering;
mod module_map;
mod mutants_apply;
