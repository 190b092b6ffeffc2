//! Shapes, resting poses, cavities and swept paths.

use nalgebra::{Point3, UnitQuaternion};

use super::*;

pub(crate) fn cube(size: f32) -> Body {
    Body::new(&ShapeSpec::Box { size: [size; 3] })
}

#[test]
fn resting_puts_the_bottom_on_the_face() {
    let b = cube(0.04);
    let p = b.resting(UnitQuaternion::identity(), 0.3, 0.1, 0.04);
    let a = b.aabb(&p);
    assert!((a.mins.z - 0.04).abs() < 1e-6);
    assert!((a.center().x - 0.3).abs() < 1e-6);
    let cup = Body::new(&ShapeSpec::Cup {
        radius: 0.04,
        height: 0.09,
        wall: 0.005,
        bottom: 0.008,
    });
    let down = cup.resting(flipped(UnitQuaternion::identity()), 0.0, 0.0, 0.0);
    assert!(!is_upright(&down));
    assert!(cup.aabb(&down).mins.z.abs() < 1e-5);
}

#[test]
fn a_falling_cube_hits_a_cube_below_but_not_beside() {
    let counter = Counter::default();
    let b = cube(0.04);
    let below = Obstacle {
        pose: b.resting(UnitQuaternion::identity(), 0.0, 0.0, 0.0),
        body: &b,
    };
    let start = Pose::translation(0.0, 0.0, 0.3);
    let end = Pose::translation(0.0, 0.0, 0.01);
    let parts = b.parts.as_ref().clone();
    assert!(path_collides(
        &parts,
        &start,
        &end,
        std::slice::from_ref(&below),
        &counter
    ));
    let aside = Pose::translation(0.1, 0.0, 0.0);
    assert!(!path_collides(
        &parts,
        &(aside * start),
        &(aside * end),
        std::slice::from_ref(&below),
        &counter
    ));
    assert!(counter.get() >= 1 && counter.broad() >= 2);
}

#[test]
fn cavity_and_opening_follow_the_pose() {
    let cup = Body::new(&ShapeSpec::Cup {
        radius: 0.045,
        height: 0.09,
        wall: 0.005,
        bottom: 0.008,
    });
    let up = cup.resting(UnitQuaternion::identity(), 0.0, 0.0, 0.0);
    assert!(cup.cavity_contains(&up, &Point3::new(0.0, 0.0, 0.03)));
    assert!(!cup.cavity_contains(&up, &Point3::new(0.0, 0.0, 0.12)));
    let region = cup.opening_region(&up).unwrap();
    assert!(region.local.translation.vector.z > 0.09);
    let down = cup.resting(flipped(UnitQuaternion::identity()), 0.0, 0.0, 0.0);
    let region = cup.opening_region(&down).unwrap();
    assert!(region.local.translation.vector.z < 0.0);
}

#[test]
fn a_capsule_rolled_about_its_length_keeps_its_bottom_where_it_lies() {
    // A banana lying along x, rolled 20° about its length (as it settles after a place):
    // its lowest point stays at the height it rests on, not the turned box's corner.
    let banana = Body::new(&ShapeSpec::Capsule {
        radius: 0.018,
        length: 0.18,
    });
    let roll = UnitQuaternion::from_axis_angle(&nalgebra::Vector3::x_axis(), 20f32.to_radians());
    let resting = banana.resting(roll, 0.3, -0.25, 0.01);
    let b = banana.aabb(&resting);
    assert!((b.mins.z - 0.01).abs() < 1e-5, "{}", b.mins.z);
    // Quarter turns keep the fast way, and the same box.
    let turned = Pose::from_parts(
        Translation3::new(0.1, 0.2, 0.0),
        UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), std::f32::consts::FRAC_PI_2),
    );
    let fast = banana.aabb(&turned);
    let exact = aabb_of(&banana.parts, &turned);
    assert!((fast.mins - exact.mins).norm() < 1e-5 && (fast.maxs - exact.maxs).norm() < 1e-5);
}
