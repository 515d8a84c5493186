//! The monodromy's columns from the step's own tangent (THEORY §9.2): the perturbed starts'
//! directions carried through one run of the period and, with a damping integrator, the
//! settled projection over the period after the settling steps.

use super::{carried_raw, deflation_steps, harmonics, starts, Columns, Settled, EPSILON};
use super::{FloquetFailure, Space};
use crate::runtime::{State, System};
use crate::solve::integrator::Integrator;
use crate::solve::Stop;
use nalgebra::DMatrix;
use std::convert::Infallible;

/// The monodromy's columns from the step's tangent: the perturbed starts' directions carried
/// through one run of the period (THEORY §9.2), measured at its end.
pub(super) fn by_tangent(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    progress: &dyn Fn(),
) -> Result<Columns, FloquetFailure> {
    let reference_failure = |failure| FloquetFailure { run: None, failure };
    let n = space.dim();
    let dim = it.direction_len();
    let mut directions = vec![0.0; n * dim];
    let mut diff = vec![0.0; dim];
    // Each start's difference from the reference start in the step's state layout.
    let z0 = starts(sys, it, space, |it, dir, sign| {
        it.state_difference(it.state(), &space.start, &mut diff);
        let col = &mut directions[dir * dim..(dir + 1) * dim];
        for (c, d) in col.iter_mut().zip(&diff) {
            *c += sign * d / (2.0 * EPSILON);
        }
        Ok(())
    })?;
    it.restart(&sys.initial).map_err(reference_failure)?;
    it.track(directions, 1.0 / space.omega);
    // With a damping integrator, the run goes on past the period by the settling steps, and
    // the period is measured again from them (`Settled`): as many as damp the consistent
    // starts' algorithmic content, at most their accelerations' share
    // (`Integrator::acceleration_share`).
    let content = it.acceleration_share();
    let (period, settle) = (it.steps(), deflation_steps(it.settings(), content));
    it.deflate_every(settle, true);
    it.extend_run(settle);
    // The directions' measure at evenly spaced steps, for the modes' time histories.
    let stride = (period / harmonics::SAMPLES).max(1);
    let (t0, mut history) = (it.state().t, Vec::new());
    history.push((0.0, z0.clone()));
    let mut zt = None;
    let (mut from, mut settled) = (None, None);
    let mut rr_history = Vec::new();
    it.run(|k, it| {
        let t = it.state().t;
        // (The settled history replaces it.)
        if settle == 0 && k % stride == 0 && k < period {
            history.push((t - t0, carried_measure(sys, it, space, it.state())));
        }
        if k == period {
            zt = Some(carried_measure(sys, it, space, it.state()));
        }
        match from {
            None if it.is_settled() => {
                from = Some((k, t));
                rr_history.push((0.0, carried_settled(sys, it, space)));
            }
            Some((s, ts)) if k - s < period && (k - s) % stride == 0 => {
                rr_history.push((t - ts, carried_settled(sys, it, space)));
            }
            Some((s, _)) if k - s == period => {
                settled = it.settled_monodromy();
            }
            _ => {}
        }
        Ok::<(), Infallible>(())
    })
    .map_err(|s| match s {
        Stop::Failed(f) => reference_failure(f),
        Stop::Stopped(never) => match never {},
    })?;
    progress();
    let zt = zt.unwrap_or_else(|| carried_measure(sys, it, space, it.state()));
    let settled = settled.and_then(|c| {
        let z = rr_history.first()?.1.clone();
        Some(Settled {
            c,
            z,
            history: rr_history,
        })
    });
    Ok(Columns {
        z0,
        zt,
        newton_iterations: it.stats().newton_iterations,
        settling: settle,
        history,
        settled,
    })
}

/// The measure of the carried directions at the integrator's current state `reference`.
fn carried_measure(
    sys: &System,
    it: &Integrator,
    space: &Space,
    reference: &State,
) -> DMatrix<f64> {
    let raw = carried_raw(sys, it, space, reference);
    let n = raw.ncols();
    let map = it.tracked_map().unwrap_or_default();
    let given = map.len() / n.max(1);
    raw * DMatrix::from_column_slice(n, given, map)
}

/// The measure of the settled directions' images now (`integrator/deflate.rs`).
fn carried_settled(sys: &System, it: &Integrator, space: &Space) -> DMatrix<f64> {
    let raw = carried_raw(sys, it, space, it.state());
    let since = it.settled_images().unwrap_or_default();
    let n = raw.ncols();
    let r = since.len() / n.max(1);
    raw * DMatrix::from_column_slice(n, r, since)
}
