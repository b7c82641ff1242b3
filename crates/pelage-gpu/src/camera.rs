//! A perspective camera, framed automatically on what is drawn or placed
//! by hand.

use glam::{Mat4, Vec3};

/// A right-handed, y-up perspective camera (wgpu clip space: depth 0..1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Where the camera is.
    pub eye: Vec3,
    /// What it looks at.
    pub target: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
}

impl Camera {
    /// Frames the box `(lo, hi)` from the side (+x), slightly above and in
    /// front: the camera backs off until all eight corners of the box fit a
    /// view of `aspect` (width / height), with a 6 % margin.
    pub fn framing(lo: Vec3, hi: Vec3, aspect: f32) -> Self {
        let fov_y_degrees = 30.0f32;
        let center = 0.5 * (lo + hi);
        let direction = Vec3::new(1.0, 0.25, 0.35).normalize();
        let forward = -direction;
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let tan_y = (0.5 * fov_y_degrees).to_radians().tan() / 1.06;
        let tan_x = tan_y * aspect;
        let mut distance: f32 = 1e-6;
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) - center;
            // The corner is at depth (d − corner·forward)… it fits when its
            // offsets over that depth are within the half-angles' tangents.
            let depth_offset = corner.dot(forward);
            distance = distance
                .max(depth_offset + corner.dot(right).abs() / tan_x)
                .max(depth_offset + corner.dot(up).abs() / tan_y);
        }
        Self {
            eye: center + direction * distance,
            target: center,
            fov_y_degrees,
        }
    }

    /// Clip-from-world matrix for a view of `aspect` (width / height),
    /// near and far planes set around `scene_radius`.
    pub fn clip_from_world(&self, aspect: f32, scene_radius: f32) -> Mat4 {
        let distance = (self.eye - self.target).length();
        let near = (distance - 2.0 * scene_radius).max(distance * 1e-3);
        let far = distance + 2.0 * scene_radius;
        let proj = glam::camera::rh::proj::directx::perspective(
            self.fov_y_degrees.to_radians(),
            aspect,
            near,
            far,
        );
        let view = glam::camera::rh::view::look_at_mat4(self.eye, self.target, Vec3::Y);
        proj * view
    }
}
