//! Runtime selection of the widest vector instructions the CPU has, for the
//! push and slide inner loops.
//!
//! The loops are plain Rust written to vectorise (contiguous slices, `min`
//! as a comparison). [`dispatch!`] compiles one copy of a function per
//! instruction set and picks one at run time, so the binary stays portable
//! to any x86-64 (or other) machine and still uses AVX2 or AVX-512 where
//! present. Results do not depend on the copy: the loops only compare and
//! take minima, which are exact in every instruction set.

/// Defines `$vis fn $name(args) -> ret` calling `$imp(args)` compiled for
/// AVX-512F, AVX2 or the baseline, whichever the CPU supports. With
/// `$imp::<A, B, C>`, the copies call `$imp::<A>`, `$imp::<B>` and
/// `$imp::<C>`: a const parameter (a block width, say) tuned per
/// instruction set.
macro_rules! dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? => $imp:ident) => {
        $crate::engine::simd::dispatch!(@copies [$(#[$meta])*] $vis $name ($($arg: $ty),*) ($($ret)?) $imp, $imp, $imp);
    };
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? => $imp:ident::<$a:literal, $b:literal, $c:literal>) => {
        $crate::engine::simd::dispatch!(@copies [$(#[$meta])*] $vis $name ($($arg: $ty),*) ($($ret)?) $imp::<$a>, $imp::<$b>, $imp::<$c>);
    };
    (@copies [$(#[$meta:meta])*] $vis:vis $name:ident ($($arg:ident: $ty:ty),*) ($($ret:ty)?) $f512:path, $f2:path, $f0:path) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,avx2,fma")]
                fn avx512($($arg: $ty),*) $(-> $ret)? {
                    $f512($($arg),*)
                }
                #[target_feature(enable = "avx2,fma")]
                fn avx2($($arg: $ty),*) $(-> $ret)? {
                    $f2($($arg),*)
                }
                if $crate::engine::simd::has_avx512() {
                    // SAFETY: the CPU supports AVX-512F, AVX2 and FMA,
                    // checked at run time just above.
                    #[allow(unsafe_code)]
                    return unsafe { avx512($($arg),*) };
                }
                if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
                    // SAFETY: the CPU supports AVX2 and FMA, checked at run
                    // time just above.
                    #[allow(unsafe_code)]
                    return unsafe { avx2($($arg),*) };
                }
            }
            $f0($($arg),*)
        }
    };
}
pub(crate) use dispatch;

/// Whether to use the AVX-512 copies: the CPU has them and the
/// `KNEEFORM_NO_AVX512` environment variable is unset (for benchmarking
/// one against the other).
#[cfg(target_arch = "x86_64")]
pub(crate) fn has_avx512() -> bool {
    static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAS.get_or_init(|| {
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::env::var_os("KNEEFORM_NO_AVX512").is_none()
    })
}
