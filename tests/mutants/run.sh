#!/bin/sh
# Mutant check: applies each patch to src/, runs the tests its `Tests:` line names (release),
# reverts, and prints KILLED (a test failed), SURVIVED (all passed), STALE (the patch no longer
# applies: the code moved; re-plant it by hand) or NO-BUILD (the mutant does not compile).
#
#   tests/mutants/run.sh                            every patch in tests/mutants/
#   tests/mutants/run.sh tests/mutants/planted_light_key.patch ...
#   RAYWAVE_MUTANT_TESTS="sampling" tests/mutants/run.sh P.patch   other tests than the patch's
#
# A patch is `git diff` output after two header lines, "Mutant: what changed" and "Tests:
# test binaries" (the [[test]] names of the two Cargo.tomls, one per kind, so `kernels` runs
# every file of tests/kernels/; `lib` for the unit tests in src/), which `git apply` skips. Run it from a
# clean work tree: it refuses to start when src/ has uncommitted changes, and it always reverts
# what it applied. Each mutant rebuilds the library in release: about a minute on 2 cores.
set -u
# A mutant's property-test failures are the mutant's, not seeds for the real code's runs.
export PROPTEST_DISABLE_FAILURE_PERSISTENCE=1
cd "$(git rev-parse --show-toplevel)" || exit 2
if ! git diff --quiet -- src; then
    echo "src/ has uncommitted changes: commit or stash them first" >&2
    exit 2
fi
[ $# -eq 0 ] && set -- tests/mutants/*.patch
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for patch in "$@"; do
    name=$(basename "$patch" .patch)
    tests=${RAYWAVE_MUTANT_TESTS:-$(sed -n 's/^Tests: //p' "$patch" | head -n 1)}
    if ! git apply "$patch" 2>/dev/null; then
        echo "STALE     $name"
        continue
    fi
    args=""
    for t in $tests; do
        if [ "$t" = lib ]; then args="$args --lib"; else args="$args --test $t"; fi
    done
    # The binary too: the tests that run it (tests/Cargo.toml's) do not build it.
    # shellcheck disable=SC2086 # one argument per word on purpose
    if ! { cargo build --release && cargo test --release --no-fail-fast $args --no-run; } >"$log" 2>&1; then
        result="NO-BUILD  $name"
    elif cargo test --release --no-fail-fast $args >"$log" 2>&1; then
        result="SURVIVED  $name  [$tests]"
    else
        failed=$(sed -n 's/^test \(.*\) \.\.\. FAILED$/\1/p' "$log" | tr '\n' ' ')
        result="KILLED    $name  by: $failed"
    fi
    git apply -R "$patch" || { echo "could not revert $patch" >&2; exit 2; }
    echo "$result"
done
