//! Checks of the built model: its topology at the initial configuration and the numbering of
//! its unknowns. Contract: reads a complete `Model` only; must not know the syntax, scopes or
//! spans beyond those the model carries.

pub mod dofs;
pub mod topology;
