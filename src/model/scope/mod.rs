//! Names and scopes: elaboration of the files (`use`, components, `for`, `if`) into scopes of
//! lazily evaluated bindings and declarations with qualified names, and the resolution of a
//! path to what it names. Contract: knows names, scopes and parameter types; must not build
//! entities (bodies, joints) or know their properties beyond the text.

pub(super) mod elaborate;
pub(super) mod env;
pub(super) mod evaluate;
pub(super) mod resolve;
pub(super) mod types;
