//! The frames of the knuckle boom, computed afresh and shared.

use super::*;

#[test]
fn coordinates_and_frames_of_the_knuckle_boom() {
    let l1 = Link::beam(10.0, 210e9, 7850.0, 0.0264, 5.89e-4)
        .unwrap()
        .with_sine_modes(3)
        .unwrap();
    let l2 = Link::beam(8.0, 210e9, 7850.0, 0.0264, 5.89e-4)
        .unwrap()
        .with_sine_modes(3)
        .unwrap();
    let l3 = Link::pendulum(6.0, 5000.0).unwrap();
    let arm = PlanarArm::new(vec![l1, l2, l3], 9.81).unwrap();
    assert_eq!(arm.n(), 9);
    assert_eq!(arm.coordinate_names()[3], "qb1_1");
    assert_eq!(arm.modal_offset(1), 6);
    let pi = std::f64::consts::PI;
    let q = [0.0, -2.0 * pi / 3.0, pi / 6.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let pose = arm.pose(&q);
    assert!((pose.origin(1) - Vector2::new(10.0, 0.0)).norm() < 1e-12);
    assert!((pose.origin(2) - Vector2::new(6.0, -8.0 * (pi / 3.0).sin())).norm() < 1e-12);
    // the pendulum hangs straight down
    assert!((pose.chord_angle(2) + pi / 2.0).abs() < 1e-12);
    assert!(arm.station(3, 1.0).is_err());
    assert!(arm.station(0, 10.5).is_err());
    // the frames shared by the arm's elements: the same bits as computed afresh, whatever
    // the order of the configurations asked for
    let q2: Vec<f64> = q.iter().map(|v| v + 0.3).collect();
    let mut frames = [arm.frames(), arm.frames()];
    for (k, qa) in [&q[..], &q2[..], &q[..]].into_iter().enumerate() {
        let (shared, fresh) = (arm.pose_in(qa, &mut frames[k % 2]), arm.pose(qa));
        assert!(matches!(shared.frames, PoseFrames::Shared(_)));
        assert_eq!(*shared.frames, *fresh.frames);
        assert_eq!(shared.chord_offset(2, 0), pose_chord(&fresh, 2, 0));
    }
    // while a pose reads the shared frames, one at another q computes its own
    let (mut fa, mut fb) = (arm.frames(), arm.frames());
    let held = arm.pose_in(&q, &mut fa);
    let other = arm.pose_in(&q2, &mut fb);
    assert!(matches!(other.frames, PoseFrames::Borrowed(_)));
    assert_eq!(*other.frames, *arm.pose(&q2).frames);
    let again = arm.pose_in(&q, &mut frames[0]);
    assert!(matches!(again.frames, PoseFrames::Shared(_)));
    assert_eq!(*held.frames, *arm.pose(&q).frames);
}

/// `c_j` computed directly.
fn pose_chord(p: &Pose<'_>, i: usize, j: usize) -> Vector2<f64> {
    p.to_frame(i, &(p.origin(i) - p.origin(j)))
}
