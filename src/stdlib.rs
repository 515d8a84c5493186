//! The standard library: `.mbd` component files compiled into the binary, so `mbd` works from
//! any directory. Their sources live in `stdlib/`; `use stdlib::NAME` reads `stdlib/NAME.mbd`.

/// (module name, source text)
pub const MODULES: &[(&str, &str)] = &[
    ("rod", include_str!("../stdlib/rod.mbd")),
    ("rotor", include_str!("../stdlib/rotor.mbd")),
    ("tower", include_str!("../stdlib/tower.mbd")),
];
