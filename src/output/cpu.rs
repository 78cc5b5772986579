//! Whether this CPU can run this binary. `.cargo/config.toml` builds for the build machine's own
//! CPU (`-C target-cpu=native`), and the compiler may then use any of that CPU's instructions in
//! any function, `main` included. A binary built on an AVX-512 node and copied to an AVX2-only
//! one died of SIGILL (exit 132) before printing a word; `main` now calls
//! [`exit_unless_supported`] first, which exits 2 naming what is missing and how to rebuild.
//!
//! ```text
//! compiled(f) = cfg!(target_feature = f)                  for each x86 feature of FEATURES
//! present(f)  = f's CPUID bit, and the OS saving the registers it needs (XCR0)
//! missing     = [f | compiled(f) && !present(f)]  -> the features, the CPU, the fix; exit 2
//! ```
//!
//! Why CPUID by hand and not `is_x86_feature_detected!`: that macro is `cfg!(target_feature =
//! f) || <run-time test>`, so for every feature the binary was compiled with, the only ones asked
//! about here, it answers `true` without looking at the CPU.
//!
//! The check runs on the CPU it doubts, compiled with the features it doubts, so it is kept to
//! CPUID, XGETBV and integer tests against constant masks (no variable shifts: with BMI2
//! compiled in those become `shrx`), and the refusal to formatting and one write. Whether the
//! compiled code keeps to that is tested, not assumed: `tests/commands/cpu_check.rs` runs the
//! real binary on emulated AVX2 CPUs without AVX-512 (valgrind's, and QEMU's Haswell), where any
//! AVX-512 instruction before the refusal would end it with SIGILL instead.

/// Where CPUID reports a feature: (leaf, sub-leaf, register).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Word {
    /// Leaf 1, ECX.
    Leaf1Ecx,
    /// Leaf 1, EDX.
    Leaf1Edx,
    /// Leaf 7 sub-leaf 0, EBX.
    Leaf7Ebx,
    /// Leaf 7 sub-leaf 0, ECX.
    Leaf7Ecx,
    /// Leaf 7 sub-leaf 0, EDX.
    Leaf7Edx,
    /// Leaf 7 sub-leaf 1, EAX.
    Leaf7Sub1Eax,
    /// Leaf 7 sub-leaf 1, EDX.
    Leaf7Sub1Edx,
    /// Leaf 0xD sub-leaf 1, EAX (the XSAVE variants).
    LeafDSub1Eax,
    /// Leaf 0x19, EBX (Key Locker).
    Leaf19Ebx,
    /// Leaf 0x8000_0001, ECX (AMD's extended bits, and LZCNT).
    Ext1Ecx,
}

/// What a feature needs besides its CPUID bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Needs {
    /// Nothing: the bit says it all.
    Bit,
    /// The OS saving the AVX registers (XCR0 bits 1 and 2): every VEX-encoded feature.
    AvxState,
    /// The OS saving the AVX-512 registers too (XCR0 bits 5 to 7).
    Avx512State,
    /// An AMD (or Hygon) CPU: on others the bit means something else or nothing.
    Amd,
}

/// One x86 target feature, as rustc spells it, with where CPUID reports it.
#[derive(Clone, Copy, Debug)]
pub struct Feature {
    /// rustc's name (`avx512f`, `sse4.1`).
    pub name: &'static str,
    /// Whether this binary was compiled with it (`cfg!(target_feature = name)`).
    pub compiled: bool,
    /// The x86-64 micro-architecture level that first includes it (1 to 4), 0 for none.
    pub level: u8,
    /// The CPUID word holding its bit.
    pub word: Word,
    /// Its bit in that word, as a mask, so that testing it needs no shift.
    pub mask: u32,
    /// What else it needs.
    pub needs: Needs,
}

macro_rules! features {
    ($($name:literal $level:literal $word:ident $bit:literal $needs:ident,)*) => {
        /// Every x86 target feature rustc can compile in on stable (the union of `rustc --print
        /// cfg` over its x86-64 CPUs), levels first, then in rustc's order.
        pub const FEATURES: &[Feature] = &[$(Feature {
            name: $name,
            compiled: cfg!(target_feature = $name),
            level: $level,
            word: Word::$word,
            mask: 1 << $bit,
            needs: Needs::$needs,
        },)*];
    };
}

// Bits from Intel's SDM vol. 2A (CPUID) and AMD's APM vol. 3 (appendix E).
features! {
    "fxsr" 1 Leaf1Edx 24 Bit,
    "sse" 1 Leaf1Edx 25 Bit,
    "sse2" 1 Leaf1Edx 26 Bit,
    "sse3" 2 Leaf1Ecx 0 Bit,
    "ssse3" 2 Leaf1Ecx 9 Bit,
    "cmpxchg16b" 2 Leaf1Ecx 13 Bit,
    "sse4.1" 2 Leaf1Ecx 19 Bit,
    "sse4.2" 2 Leaf1Ecx 20 Bit,
    "popcnt" 2 Leaf1Ecx 23 Bit,
    "fma" 3 Leaf1Ecx 12 AvxState,
    "movbe" 3 Leaf1Ecx 22 Bit,
    "xsave" 3 Leaf1Ecx 26 AvxState,
    "avx" 3 Leaf1Ecx 28 AvxState,
    "f16c" 3 Leaf1Ecx 29 AvxState,
    "bmi1" 3 Leaf7Ebx 3 Bit,
    "avx2" 3 Leaf7Ebx 5 AvxState,
    "bmi2" 3 Leaf7Ebx 8 Bit,
    "lzcnt" 3 Ext1Ecx 5 Bit,
    "avx512f" 4 Leaf7Ebx 16 Avx512State,
    "avx512dq" 4 Leaf7Ebx 17 Avx512State,
    "avx512cd" 4 Leaf7Ebx 28 Avx512State,
    "avx512bw" 4 Leaf7Ebx 30 Avx512State,
    "avx512vl" 4 Leaf7Ebx 31 Avx512State,
    "pclmulqdq" 0 Leaf1Ecx 1 Bit,
    "aes" 0 Leaf1Ecx 25 Bit,
    "rdrand" 0 Leaf1Ecx 30 Bit,
    "rdseed" 0 Leaf7Ebx 18 Bit,
    "adx" 0 Leaf7Ebx 19 Bit,
    "sha" 0 Leaf7Ebx 29 Bit,
    "gfni" 0 Leaf7Ecx 8 Bit,
    "vaes" 0 Leaf7Ecx 9 AvxState,
    "vpclmulqdq" 0 Leaf7Ecx 10 AvxState,
    "xsaveopt" 0 LeafDSub1Eax 0 AvxState,
    "xsavec" 0 LeafDSub1Eax 1 AvxState,
    "xsaves" 0 LeafDSub1Eax 3 AvxState,
    "sse4a" 0 Ext1Ecx 6 Amd,
    "tbm" 0 Ext1Ecx 21 Amd,
    "avx512ifma" 0 Leaf7Ebx 21 Avx512State,
    "avx512vbmi" 0 Leaf7Ecx 1 Avx512State,
    "avx512vbmi2" 0 Leaf7Ecx 6 Avx512State,
    "avx512vnni" 0 Leaf7Ecx 11 Avx512State,
    "avx512bitalg" 0 Leaf7Ecx 12 Avx512State,
    "avx512vpopcntdq" 0 Leaf7Ecx 14 Avx512State,
    "avx512vp2intersect" 0 Leaf7Edx 8 Avx512State,
    "avx512fp16" 0 Leaf7Edx 23 Avx512State,
    "avx512bf16" 0 Leaf7Sub1Eax 5 Avx512State,
    "sha512" 0 Leaf7Sub1Eax 0 AvxState,
    "sm3" 0 Leaf7Sub1Eax 1 AvxState,
    "sm4" 0 Leaf7Sub1Eax 2 AvxState,
    "avxvnni" 0 Leaf7Sub1Eax 4 AvxState,
    "avxifma" 0 Leaf7Sub1Eax 23 AvxState,
    "avxvnniint8" 0 Leaf7Sub1Edx 4 AvxState,
    "avxneconvert" 0 Leaf7Sub1Edx 5 AvxState,
    "avxvnniint16" 0 Leaf7Sub1Edx 10 AvxState,
    "kl" 0 Leaf19Ebx 0 Bit,
    "widekl" 0 Leaf19Ebx 2 Bit,
}

/// What CPUID and XGETBV said about this CPU, read once.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cpuid {
    /// The words of [`Word`], in its order (0 for a leaf the CPU does not have).
    words: [u32; 10],
    /// An AMD or Hygon CPU.
    amd: bool,
    /// An Intel CPU.
    intel: bool,
    /// The OS saves the AVX registers.
    avx_state: bool,
    /// The OS saves the AVX-512 registers.
    avx512_state: bool,
}

impl Cpuid {
    /// This CPU.
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    #[allow(unused_unsafe)] // CPUID became a safe intrinsic after our minimum Rust.
    pub fn read() -> Cpuid {
        #[cfg(target_arch = "x86")]
        use std::arch::x86::{__cpuid_count, _xgetbv};
        #[cfg(target_arch = "x86_64")]
        use std::arch::x86_64::{__cpuid_count, _xgetbv};
        // SAFETY: every x86-64 CPU has CPUID, and a leaf above the maximum only returns zeros
        // or the highest leaf's values, which the maxima below keep us from reading.
        let cpuid = |leaf: u32, sub: u32| unsafe { __cpuid_count(leaf, sub) };
        let mut c = Cpuid::default();
        let id = cpuid(0, 0);
        let max = id.eax;
        // The vendor string is EBX, EDX, ECX: "Auth" "enti" "cAMD", "Genu" "ineI" "ntel".
        c.amd = (id.ebx, id.edx, id.ecx) == (0x6874_7541, 0x6974_6e65, 0x444d_4163)
            || (id.ebx, id.edx, id.ecx) == (0x6f67_7948, 0x6e65_476e, 0x656e_6975);
        c.intel = (id.ebx, id.edx, id.ecx) == (0x756e_6547, 0x4965_6e69, 0x6c65_746e);
        if max >= 1 {
            let l1 = cpuid(1, 0);
            c.words[Word::Leaf1Ecx as usize] = l1.ecx;
            c.words[Word::Leaf1Edx as usize] = l1.edx;
        }
        if max >= 7 {
            let l7 = cpuid(7, 0);
            c.words[Word::Leaf7Ebx as usize] = l7.ebx;
            c.words[Word::Leaf7Ecx as usize] = l7.ecx;
            c.words[Word::Leaf7Edx as usize] = l7.edx;
            if l7.eax >= 1 {
                let l7s1 = cpuid(7, 1);
                c.words[Word::Leaf7Sub1Eax as usize] = l7s1.eax;
                c.words[Word::Leaf7Sub1Edx as usize] = l7s1.edx;
            }
            // Leaf 0x19 exists when leaf 7 says Key Locker (ECX bit 23).
            if max >= 0x19 && l7.ecx & (1 << 23) != 0 {
                c.words[Word::Leaf19Ebx as usize] = cpuid(0x19, 0).ebx;
            }
        }
        if max >= 0xd {
            c.words[Word::LeafDSub1Eax as usize] = cpuid(0xd, 1).eax;
        }
        if cpuid(0x8000_0000, 0).eax >= 0x8000_0001 {
            c.words[Word::Ext1Ecx as usize] = cpuid(0x8000_0001, 0).ecx;
        }
        // XGETBV needs OSXSAVE (leaf 1 ECX bit 27): the OS has enabled XSAVE and says, in
        // XCR0, which register files it saves across context switches.
        if c.words[Word::Leaf1Ecx as usize] & (1 << 27) != 0 {
            // SAFETY: OSXSAVE is set, so XGETBV exists and XCR0 (register 0) is readable.
            let xcr0 = unsafe { _xgetbv(0) };
            c.avx_state = xcr0 & 0b110 == 0b110;
            c.avx512_state = c.avx_state && xcr0 & 0b1110_0000 == 0b1110_0000;
        }
        c
    }

    /// Not an x86 CPU: no x86 feature.
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    pub fn read() -> Cpuid {
        Cpuid::default()
    }

    /// Whether this CPU has `feature`, its bit and what else it needs.
    pub fn has(&self, feature: &Feature) -> bool {
        let bit = self.words[feature.word as usize] & feature.mask != 0;
        let needs = match feature.needs {
            Needs::Bit => true,
            Needs::AvxState => self.avx_state,
            Needs::Avx512State => self.avx512_state,
            Needs::Amd => self.amd,
        };
        // Some Intel CPUs without AVX report BMI1 and BMI2 that they do not have (Skylake
        // erratum SKL052), as std's detection also allows for.
        let erratum = matches!(feature.name, "bmi1" | "bmi2") && self.intel && !self.avx_state;
        bit && needs && !erratum
    }
}

/// The features of `features` this binary was compiled with that `has` says the CPU lacks, in
/// table order: the check itself, over any table and any detector.
pub fn missing(features: &[Feature], has: impl Fn(&Feature) -> bool) -> Vec<&'static str> {
    features
        .iter()
        .filter(|f| f.compiled && !has(f))
        .map(|f| f.name)
        .collect()
}

/// The features `has` says the CPU has that this binary was not compiled with.
pub fn unused(features: &[Feature], has: impl Fn(&Feature) -> bool) -> Vec<&'static str> {
    features
        .iter()
        .filter(|f| !f.compiled && has(f))
        .map(|f| f.name)
        .collect()
}

/// The `-C target-cpu` to suggest for a CPU: the highest x86-64 level (`x86-64-v4` to
/// `x86-64`) all of whose features `has` finds.
fn suggested_target(features: &[Feature], has: impl Fn(&Feature) -> bool) -> &'static str {
    let level_ok = |level: u8| {
        features
            .iter()
            .filter(|f| (1..=level).contains(&f.level))
            .all(&has)
    };
    match (2..=4).rev().find(|&l| level_ok(l)) {
        Some(4) => "x86-64-v4",
        Some(3) => "x86-64-v3",
        Some(_) => "x86-64-v2",
        None => "x86-64",
    }
}

/// The refusal: the missing features, the CPU, how this binary was built, and the fix.
pub fn refusal(missing: &[&str], cpu: &str, rustflags: &str, target_cpu: &str) -> String {
    let built = if rustflags.is_empty() {
        "without RUSTFLAGS".to_string()
    } else {
        format!("with RUSTFLAGS `{rustflags}`")
    };
    format!(
        "error: this raywave was compiled for CPU features that this CPU ({cpu}) lacks: {}\n\
         It was built {built}, for another machine's CPU; it would die of an illegal \
         instruction here.\n\
         Rebuild it for the oldest CPU it runs on, here:\n  \
         RUSTFLAGS=\"-C target-cpu={target_cpu}\" cargo build --release\n\
         or build it on this machine (docs/SCALING.md, \"One binary for every node\").\n",
        missing.join(", ")
    )
}

/// Returns when this CPU has every x86 feature this binary was compiled with; otherwise prints
/// [`refusal`] and exits with status 2. The first thing `main` does, before any code that may
/// use those features.
pub fn exit_unless_supported() {
    let cpu = Cpuid::read();
    let missing = missing(FEATURES, |f| cpu.has(f));
    if missing.is_empty() {
        return;
    }
    let message = refusal(
        &missing,
        &super::machine::cpu_model(),
        env!("RAYWAVE_RUSTFLAGS"),
        suggested_target(FEATURES, |f| cpu.has(f)),
    );
    use std::io::Write;
    // Nothing to do if standard error is gone: the exit status still says it.
    let _ = std::io::stderr().write_all(message.as_bytes());
    std::process::exit(2);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn feature(name: &'static str, compiled: bool, level: u8) -> Feature {
        Feature {
            name,
            compiled,
            level,
            word: Word::Leaf1Ecx,
            mask: 1,
            needs: Needs::Bit,
        }
    }

    #[test]
    fn a_compiled_feature_the_cpu_lacks_is_missing_and_named_in_the_refusal() {
        let table = [
            feature("sse2", true, 1),
            feature("avx2", true, 3),
            feature("avx512f", true, 4),
            feature("avx512bw", true, 4),
            feature("sse4a", false, 0),
        ];
        // An AVX2 CPU without AVX-512 and without SSE4a (an Intel one).
        let has = |f: &Feature| !f.name.starts_with("avx512") && f.name != "sse4a";
        let lacks = missing(&table, has);
        // sse4a is absent too, but this build does not use it.
        assert_eq!(lacks, ["avx512f", "avx512bw"]);
        assert_eq!(suggested_target(&table, has), "x86-64-v3");
        let message = refusal(
            &lacks,
            "Intel(R) Xeon(R) CPU E5-2680 v3",
            "-C target-cpu=native",
            "x86-64-v3",
        );
        for needle in [
            "avx512f, avx512bw",
            "(Intel(R) Xeon(R) CPU E5-2680 v3)",
            "`-C target-cpu=native`",
            "RUSTFLAGS=\"-C target-cpu=x86-64-v3\" cargo build --release",
            "build it on this machine",
        ] {
            assert!(message.contains(needle), "{needle:?} not in:\n{message}");
        }
        // The CPU has every feature: nothing missing.
        assert!(missing(&table, |_| true).is_empty());
        assert_eq!(unused(&table, |_| true), ["sse4a"]);
    }

    #[test]
    fn a_bit_counts_only_with_the_os_state_and_the_vendor_it_needs() {
        let named = |name: &str| *FEATURES.iter().find(|f| f.name == name).unwrap();
        // Every bit set: what decides is the rest.
        let all = Cpuid {
            words: [u32::MAX; 10],
            amd: false,
            intel: true,
            avx_state: true,
            avx512_state: true,
        };
        for f in FEATURES {
            assert!(all.has(f) || f.needs == Needs::Amd, "{}", f.name);
        }
        // The OS saves the AVX registers but not the AVX-512 ones (XCR0 bits 5 to 7 clear).
        let no_zmm = Cpuid {
            avx512_state: false,
            ..all
        };
        assert!(!no_zmm.has(&named("avx512f")) && !no_zmm.has(&named("avx512bf16")));
        assert!(no_zmm.has(&named("avx2")) && no_zmm.has(&named("sse4.2")));
        // Nor the AVX ones: no VEX feature, and an Intel CPU's BMI bits are its erratum.
        let no_ymm = Cpuid {
            avx_state: false,
            avx512_state: false,
            ..all
        };
        for name in [
            "avx", "avx2", "fma", "f16c", "xsave", "vaes", "bmi1", "bmi2",
        ] {
            assert!(!no_ymm.has(&named(name)), "{name}");
        }
        assert!(no_ymm.has(&named("popcnt")) && no_ymm.has(&named("lzcnt")));
        let amd_no_ymm = Cpuid {
            amd: true,
            intel: false,
            ..no_ymm
        };
        assert!(amd_no_ymm.has(&named("bmi1")) && amd_no_ymm.has(&named("sse4a")));
        // SSE4a and TBM's bits mean them on AMD only.
        assert!(!all.has(&named("sse4a")) && !all.has(&named("tbm")));
        // A bit clear is absent, whatever else holds.
        let mut no_avx512f = all;
        no_avx512f.words[Word::Leaf7Ebx as usize] &= !(1 << 16);
        assert!(!no_avx512f.has(&named("avx512f")) && no_avx512f.has(&named("avx512dq")));
    }

    #[test]
    fn the_suggestion_is_the_highest_level_the_cpu_has_whole() {
        let levels: Vec<Feature> = FEATURES.iter().copied().filter(|f| f.level > 0).collect();
        let up_to = |l: u8| move |f: &Feature| f.level <= l;
        assert_eq!(suggested_target(&levels, up_to(4)), "x86-64-v4");
        assert_eq!(suggested_target(&levels, up_to(3)), "x86-64-v3");
        assert_eq!(suggested_target(&levels, up_to(2)), "x86-64-v2");
        assert_eq!(suggested_target(&levels, up_to(1)), "x86-64");
        // One v3 feature short (an AVX CPU without AVX2): v2.
        let no_avx2 = |f: &Feature| f.name != "avx2";
        assert_eq!(suggested_target(&levels, no_avx2), "x86-64-v2");
    }

    /// `rustc --print cfg` with `args`: the target features it enables.
    fn rustc_features(args: &[&str]) -> Option<Vec<String>> {
        let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
        let out = std::process::Command::new(rustc)
            .args(["--print", "cfg"])
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())?;
        Some(
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .filter_map(|l| l.strip_prefix("target_feature=\""))
                .map(|l| l.trim_end_matches('"').to_string())
                .collect(),
        )
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn the_table_holds_every_feature_rustc_enables_and_its_levels() {
        let names: Vec<&str> = FEATURES.iter().map(|f| f.name).collect();
        // The CPUs whose feature sets together hold every stable x86 feature (AMD's tbm and
        // sse4a, Intel's Key Locker, SM3/SM4, AVX-512 FP16 and VP2INTERSECT among them).
        for cpu in [
            "native",
            "znver4",
            "znver5",
            "bdver4",
            "sapphirerapids",
            "graniterapids",
            "tigerlake",
            "arrowlake-s",
            "pantherlake",
            "diamondrapids",
        ] {
            let Some(enabled) = rustc_features(&[&format!("-Ctarget-cpu={cpu}")]) else {
                // A CPU this rustc does not know yet.
                continue;
            };
            for f in &enabled {
                assert!(
                    names.contains(&f.as_str()),
                    "rustc enables {f} for {cpu}, and the check does not know it"
                );
            }
        }
        // Each level's features are exactly those of rustc's x86-64-vN.
        for level in 1..=4u8 {
            let cpu = match level {
                1 => "x86-64".to_string(),
                l => format!("x86-64-v{l}"),
            };
            let enabled = rustc_features(&[&format!("-Ctarget-cpu={cpu}")]).expect("rustc");
            let mut ours: Vec<&str> = FEATURES
                .iter()
                .filter(|f| (1..=level).contains(&f.level))
                .map(|f| f.name)
                .collect();
            let mut theirs: Vec<&str> = enabled.iter().map(String::as_str).collect();
            ours.sort_unstable();
            theirs.sort_unstable();
            assert_eq!(ours, theirs, "{cpu}");
        }
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn this_cpu_has_what_this_binary_was_compiled_with_and_what_linux_lists() {
        let cpu = Cpuid::read();
        // The test runs, so the CPU has every compiled feature.
        assert_eq!(missing(FEATURES, |f| cpu.has(f)), Vec::<&str>::new());
        // And CPUID read by hand agrees with the kernel's own reading, flag by flag.
        let Ok(text) = std::fs::read_to_string("/proc/cpuinfo") else {
            return;
        };
        let flags: Vec<&str> = text
            .lines()
            .find(|l| l.starts_with("flags"))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.split_whitespace().collect())
            .unwrap_or_default();
        let mut disagree = Vec::new();
        for f in FEATURES {
            // Linux's names: `_` for `.`, underscores after avx512 and avx_, sha_ni, ...
            let linux = match f.name {
                "cmpxchg16b" => "cx16".to_string(),
                "sse3" => "pni".to_string(),
                "lzcnt" => "abm".to_string(),
                "sha" => "sha_ni".to_string(),
                "avxvnni" => "avx_vnni".to_string(),
                "avxifma" => "avx_ifma".to_string(),
                "avxvnniint8" => "avx_vnni_int8".to_string(),
                "avxneconvert" => "avx_ne_convert".to_string(),
                "avxvnniint16" => "avx_vnni_int16".to_string(),
                "avx512vbmi" | "avx512ifma" | "avx512cd" | "avx512bw" | "avx512dq" | "avx512vl"
                | "avx512f" => f.name.to_string(),
                n if n.starts_with("avx512") => format!("avx512_{}", &n[6..]),
                n => n.replace('.', "_"),
            };
            // Linux may leave out what CPUID reports: names only kernels newer than some know,
            // and RDSEED, which it clears on AMD Zen 5 (whose RDSEED can return 0 as success).
            // It never lists what CPUID does not report, so that direction is always ours.
            let may_omit = [
                "sha512",
                "sm3",
                "sm4",
                "kl",
                "widekl",
                "avx_ifma",
                "avx_vnni_int8",
                "avx_ne_convert",
                "avx_vnni_int16",
                "rdseed",
            ];
            let listed = flags.contains(&linux.as_str());
            if listed != cpu.has(f) && (listed || !may_omit.contains(&linux.as_str())) {
                disagree.push(format!(
                    "{}: CPUID {}, Linux's {linux} {}",
                    f.name,
                    cpu.has(f),
                    listed
                ));
            }
        }
        assert_eq!(
            disagree,
            Vec::<String>::new(),
            "CPUID and /proc/cpuinfo disagree"
        );
    }
}
