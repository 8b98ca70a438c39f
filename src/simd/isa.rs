//! The instruction sets the multi-sample kernels are compiled for, chosen at run time: one
//! binary or wheel runs on every x86-64 processor and uses the widest vectors each one has.

use std::sync::OnceLock;

/// An instruction set the multi-sample kernels ([`crate::algorithms::batch`]) run on.
///
/// | variant    | samples side by side | needs                                        |
/// |------------|----------------------|----------------------------------------------|
/// | `Avx512`   | 8                    | x86-64 with AVX-512 F, VL, DQ, AVX2 and FMA   |
/// | `Avx2Fma`  | 4 (8 in pairs: RNEA, M)  | x86-64 with AVX2 and FMA                      |
/// | `Scalar`   | 1                    | nothing: the one-sample algorithms, in a loop |
///
/// The vector paths fuse multiplies and adds (FMA), so their results differ from the scalar
/// path's by rounding only (tested to 1e-12 relative).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Isa {
    /// 8 `f64` lanes in 512-bit registers.
    Avx512,
    /// 4 `f64` lanes in 256-bit registers.
    Avx2Fma,
    /// One sample at a time, the one-sample algorithms.
    Scalar,
}

impl Isa {
    /// Every instruction set, widest first.
    pub const ALL: [Isa; 3] = [Isa::Avx512, Isa::Avx2Fma, Isa::Scalar];

    /// The widest instruction set this processor has (detected once, then cached), capped by
    /// the environment variable [`Isa::CAP_VARIABLE`] when it names one (`avx512`, `avx2+fma`
    /// or `scalar`: the widest available set no wider than it, to reproduce what a machine
    /// without AVX-512 runs, or to set the vector paths aside). A value that names no set is
    /// reported once on standard error and not used.
    pub fn detect() -> Isa {
        static BEST: OnceLock<Isa> = OnceLock::new();
        *BEST.get_or_init(|| {
            let value = std::env::var(Self::CAP_VARIABLE).ok();
            let cap = match value.as_deref().map(Isa::from_name) {
                Some(None) => {
                    eprintln!(
                        "perturbid_rs: {}={:?} names no instruction set (avx512, avx2+fma, \
                         scalar): ignored, the widest available is used",
                        Self::CAP_VARIABLE,
                        value.unwrap_or_default()
                    );
                    Isa::Avx512
                }
                Some(Some(cap)) => cap,
                None => Isa::Avx512,
            };
            Isa::best_up_to(cap)
        })
    }

    /// The environment variable that caps [`Isa::detect`]: `PERTURBID_SIMD`.
    pub const CAP_VARIABLE: &'static str = "PERTURBID_SIMD";

    /// The widest instruction set this processor has that is no wider than `cap`.
    pub fn best_up_to(cap: Isa) -> Isa {
        Isa::ALL
            .into_iter()
            .filter(|isa| isa.lanes() <= cap.lanes())
            .find(|isa| isa.is_available())
            .unwrap_or(Isa::Scalar)
    }

    /// Whether this processor runs the kernels of `self`.
    pub fn is_available(self) -> bool {
        match self {
            Isa::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2Fma => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                Isa::Avx2Fma.is_available()
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                    && std::arch::is_x86_feature_detected!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The instruction sets this processor runs, widest first (always ends with `Scalar`).
    pub fn available() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|i| i.is_available()).collect()
    }

    /// Samples processed side by side.
    pub fn lanes(self) -> usize {
        match self {
            Isa::Avx512 => 8,
            Isa::Avx2Fma => 4,
            Isa::Scalar => 1,
        }
    }

    /// A short name: `"avx512"`, `"avx2+fma"` or `"scalar"`.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx512 => "avx512",
            Isa::Avx2Fma => "avx2+fma",
            Isa::Scalar => "scalar",
        }
    }

    /// The instruction set named `name` (as [`Isa::name`] gives it; `"avx2"` too).
    pub fn from_name(name: &str) -> Option<Isa> {
        match name.trim().to_ascii_lowercase().as_str() {
            "avx512" | "avx-512" => Some(Isa::Avx512),
            "avx2+fma" | "avx2" => Some(Isa::Avx2Fma),
            "scalar" => Some(Isa::Scalar),
            _ => None,
        }
    }
}

impl std::fmt::Display for Isa {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detection_picks_an_available_set_and_names_round_trip() {
        assert!(Isa::detect().is_available());
        assert_eq!(Isa::available().last(), Some(&Isa::Scalar));
        for isa in Isa::ALL {
            assert_eq!(Isa::from_name(isa.name()), Some(isa));
        }
        assert_eq!(Isa::from_name("sse9"), None);
        // a cap never gives a wider set, nor one this processor lacks
        for cap in Isa::ALL {
            let got = Isa::best_up_to(cap);
            assert!(
                got.lanes() <= cap.lanes() && got.is_available(),
                "{cap}: {got}"
            );
            if cap.is_available() {
                assert_eq!(got, cap);
            }
        }
    }
}
