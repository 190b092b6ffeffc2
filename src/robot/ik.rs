//! Inverse kinematics of one arm: damped least squares on the flange's position and
//! orientation error, with the seven-axis arm's spare degree of freedom (the elbow's
//! swivel) spent in the Jacobian's null space on staying near the start configuration and
//! away from the joint limits. Several starts (the given one, then random ones from a
//! seed) are tried; of the solutions found, the one nearest the start wins. Deterministic
//! for a seed.

use nalgebra::{Isometry3, Matrix6, SMatrix, SVector, Vector3, Vector6};

use super::chain::Chain;
use super::rng::SplitMix;

/// How hard to look for a solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// Starts tried at most (the first is the given configuration).
    pub starts: usize,
    /// Solutions to collect before choosing the nearest.
    pub solutions: usize,
    pub iterations: usize,
    /// Accepted position error (metres) and orientation error (radians).
    pub position_tolerance: f64,
    pub angle_tolerance: f64,
    /// Damping of the least-squares step.
    pub damping: f64,
    pub seed: u64,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions {
            starts: 24,
            solutions: 3,
            iterations: 300,
            position_tolerance: 1e-5,
            angle_tolerance: 1e-4,
            damping: 0.02,
            seed: 39,
        }
    }
}

/// Joint values that put an arm's flange at a pose.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    /// Index of the arm (into the arms given).
    pub arm: usize,
    pub q: Vec<f64>,
    pub position_error: f64,
    pub angle_error: f64,
}

/// Why no solution was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("pose {pose} is out of reach of {arms} (no joint values within the limits reach it)")]
pub struct Unreachable {
    /// The pose, as position and roll-pitch-yaw.
    pub pose: String,
    /// The arms that were tried.
    pub arms: String,
}

/// The pose as people read it: position in metres, then roll, pitch, yaw in degrees.
pub fn describe_pose(pose: &Isometry3<f64>) -> String {
    let t = pose.translation.vector;
    let (r, p, y) = pose.rotation.euler_angles();
    format!(
        "({:.3}, {:.3}, {:.3}) m, rpy ({:.1}, {:.1}, {:.1})°",
        t.x,
        t.y,
        t.z,
        r.to_degrees(),
        p.to_degrees(),
        y.to_degrees()
    )
}

const DOF: usize = 7;
type Jacobian = SMatrix<f64, 6, DOF>;

/// Joint values within `chain`'s limits that put its flange at `target` (in the chain's
/// root frame), starting from `start`.
pub fn solve(
    chain: &Chain,
    target: &Isometry3<f64>,
    start: &[f64],
    options: &IkOptions,
) -> Option<(Vec<f64>, f64, f64)> {
    if chain.dof() != DOF || start.len() != DOF {
        return None;
    }
    let mut rng = SplitMix::new(options.seed);
    let mut found: Vec<(Vec<f64>, f64, f64)> = Vec::new();
    let mut frames = Vec::with_capacity(DOF);
    for attempt in 0..options.starts {
        let seed: Vec<f64> = if attempt == 0 {
            clamp(chain, start)
        } else {
            chain
                .joints
                .iter()
                .map(|j| j.lower + rng.unit() * (j.upper - j.lower))
                .collect()
        };
        if let Some(solution) = descend(chain, target, seed, start, options, &mut frames) {
            found.push(solution);
            if found.len() >= options.solutions {
                break;
            }
        }
    }
    found
        .into_iter()
        .min_by(|a, b| distance(&a.0, start).total_cmp(&distance(&b.0, start)))
}

/// Try the arms nearest first (by the distance from each arm's first joint to the target)
/// and return the first solution. `starts[i]` is arm `i`'s current configuration.
pub fn nearest_arm_solution(
    arms: &[Chain],
    target: &Isometry3<f64>,
    starts: &[Vec<f64>],
    options: &IkOptions,
) -> Result<IkSolution, Unreachable> {
    let mut order: Vec<(usize, f64)> = arms
        .iter()
        .enumerate()
        .filter_map(|(i, arm)| {
            let shoulder = arm.joints.first()?.before.translation.vector;
            Some((i, (target.translation.vector - shoulder).norm()))
        })
        .collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (i, _) in order {
        let Some(start) = starts.get(i) else {
            continue;
        };
        if let Some((q, position_error, angle_error)) = solve(&arms[i], target, start, options) {
            return Ok(IkSolution {
                arm: i,
                q,
                position_error,
                angle_error,
            });
        }
    }
    Err(Unreachable {
        pose: describe_pose(target),
        arms: arms
            .iter()
            .map(|a| a.tip.as_str())
            .collect::<Vec<_>>()
            .join(" and "),
    })
}

fn clamp(chain: &Chain, q: &[f64]) -> Vec<f64> {
    chain
        .joints
        .iter()
        .zip(q)
        .map(|(j, &v)| v.clamp(j.lower, j.upper))
        .collect()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>()
}

/// The flange's position and orientation error at `q` (world frame), and the frames.
fn error_at(
    chain: &Chain,
    target: &Isometry3<f64>,
    q: &[f64],
    frames: &mut Vec<Isometry3<f64>>,
) -> (Vector6<f64>, Isometry3<f64>) {
    chain.frames(q, frames);
    let flange = frames[DOF - 1] * chain.flange;
    let dp = target.translation.vector - flange.translation.vector;
    let dr = (target.rotation * flange.rotation.inverse()).scaled_axis();
    (Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z), flange)
}

/// Levenberg–Marquardt (damped least squares whose damping shrinks after a step that
/// lowered the error and grows after one that did not) from `q` towards `target`; the
/// null-space step pulls towards `rest` and the middle of each joint's range. Returns the
/// joint values and the remaining errors when both tolerances are met.
fn descend(
    chain: &Chain,
    target: &Isometry3<f64>,
    mut q: Vec<f64>,
    rest: &[f64],
    options: &IkOptions,
    frames: &mut Vec<Isometry3<f64>>,
) -> Option<(Vec<f64>, f64, f64)> {
    let mut lambda = options.damping;
    let (mut error, mut flange) = error_at(chain, target, &q, frames);
    let mut trial = vec![0.0; DOF];
    for _ in 0..options.iterations {
        let (pe, ae) = (
            error.fixed_rows::<3>(0).norm(),
            error.fixed_rows::<3>(3).norm(),
        );
        if pe < options.position_tolerance && ae < options.angle_tolerance {
            return Some((q, pe, ae));
        }
        chain.frames(&q, frames);
        let mut jac = Jacobian::zeros();
        for (i, (joint, frame)) in chain.joints.iter().zip(frames.iter()).enumerate() {
            let axis: Vector3<f64> = frame.rotation * joint.axis.into_inner();
            let linear = if joint.rotates {
                axis.cross(&(flange.translation.vector - frame.translation.vector))
            } else {
                axis
            };
            let angular = if joint.rotates {
                axis
            } else {
                Vector3::zeros()
            };
            jac.fixed_view_mut::<3, 1>(0, i).copy_from(&linear);
            jac.fixed_view_mut::<3, 1>(3, i).copy_from(&angular);
        }
        let jjt: Matrix6<f64> = jac * jac.transpose() + Matrix6::identity() * (lambda * lambda);
        let pseudo = jac.transpose() * jjt.try_inverse()?;
        let task: SVector<f64, DOF> = pseudo * error;
        // The spare degree of freedom: towards the rest pose and the middle of each range,
        // once the flange is near its target (taken only when the error still falls).
        let spare = (pe < 0.01).then(|| {
            let preference = SVector::<f64, DOF>::from_fn(|i, _| {
                let j = &chain.joints[i];
                let middle = (j.lower + j.upper) / 2.0;
                let half = ((j.upper - j.lower) / 2.0).max(1e-9);
                0.1 * (rest[i] - q[i]) + 0.02 * (middle - q[i]) / half
            });
            task + (SMatrix::<f64, DOF, DOF>::identity() - pseudo * jac) * preference
        });
        let mut improved = false;
        for mut step in spare.into_iter().chain([task]) {
            let largest = step.amax();
            if largest > 0.4 {
                step *= 0.4 / largest;
            }
            for (i, j) in chain.joints.iter().enumerate() {
                trial[i] = (q[i] + step[i]).clamp(j.lower, j.upper);
            }
            let (next, next_flange) = error_at(chain, target, &trial, frames);
            if next.norm() < error.norm() {
                q.copy_from_slice(&trial);
                error = next;
                flange = next_flange;
                improved = true;
                break;
            }
        }
        if improved {
            lambda = (lambda * 0.5).max(1e-4);
        } else {
            lambda *= 4.0;
            if lambda > 10.0 {
                return None;
            }
        }
    }
    None
}
