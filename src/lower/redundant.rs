//! Redundant but consistent joints (W0303): the rows each drops at the start
//! ([`crate::runtime::joints::select_dropped`]: the rows the others span), a slot per joint
//! in the state's masks, and the joints listed on the system for the minimum-norm reactions
//! and the run's re-selection as the mechanism moves.
//!
//! Contract: marks the lowered joints; the model check has decided that the dependency is
//! consistent (no drive in it).

use crate::runtime::joints::select_dropped;
use crate::runtime::{Element, State, UnknownKind};

/// Gives the joint elements `joints` their slots and `st` their masks at the start:
/// `surplus` rows dropped (as many as the model check counted).
pub fn drop_surplus(
    elements: &mut [Element],
    joints: &[usize],
    unknowns: &[UnknownKind],
    st: &mut State,
    length: f64,
    surplus: usize,
) {
    for (slot, &e) in joints.iter().enumerate() {
        if let Element::Joint(j) = &mut elements[e] {
            j.slot = Some(slot);
        }
    }
    st.dropped = select_dropped(elements, joints, unknowns, st, length, Some(surplus));
}
