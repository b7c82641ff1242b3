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
        Self::framing_with_fov(lo, hi, aspect, 30.0)
    }

    /// [`Self::framing`] for a vertical field of view of `fov_y_degrees`.
    pub fn framing_with_fov(lo: Vec3, hi: Vec3, aspect: f32, fov_y_degrees: f32) -> Self {
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
        let view = glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up());
        proj * view
    }

    /// Pixels per unit of size at unit view depth, on an image `height`
    /// pixels high: a thing `w` wide at depth `z` is `w · f / z` pixels.
    /// From the field of view alone, whichever way the camera looks.
    pub fn focal_length_px(&self, height: u32) -> f32 {
        0.5 * height as f32 / (0.5 * self.fov_y_degrees.to_radians()).tan()
    }

    /// The view's up direction: world +y, or, looking straight down or up
    /// (where +y is the view direction and says nothing about roll), the
    /// world −z or +z, so a top-down view shows +x to the right and −z up,
    /// as Blender's and Houdini's top views do.
    pub fn up(&self) -> Vec3 {
        let forward = (self.target - self.eye).normalize_or_zero();
        if forward.cross(Vec3::Y).length_squared() > 1e-8 {
            Vec3::Y
        } else if forward.y < 0.0 {
            Vec3::NEG_Z
        } else {
            Vec3::Z
        }
    }

    /// A scene file's camera: what it places by hand, the rest framed on
    /// the box `(lo, hi)` at its field of view.
    pub fn from_scene(
        placed: &pelage::shell::SceneCamera,
        lo: Vec3,
        hi: Vec3,
        aspect: f32,
    ) -> Self {
        let framed = Self::framing_with_fov(lo, hi, aspect, placed.fov_y_degrees);
        let target = placed.target.unwrap_or(framed.target);
        Self {
            eye: placed.eye.unwrap_or(target + (framed.eye - framed.target)),
            target,
            fov_y_degrees: placed.fov_y_degrees,
        }
    }
}

/// A camera that orbits a target, as in Blender's and Houdini's viewports:
/// drag to turn around the target, pan to move the target in the view
/// plane, zoom to move in. Angles are kept, not the eye, so orbiting never
/// drifts and the view never rolls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// What the camera turns around.
    pub target: Vec3,
    /// Angle around the y axis, radians (0: looking along −z).
    pub yaw: f32,
    /// Angle above the horizon, radians, kept inside ±89°.
    pub pitch: f32,
    /// Distance from the eye to the target.
    pub distance: f32,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
}

const PITCH_LIMIT: f32 = 89.0 * std::f32::consts::PI / 180.0;

impl OrbitCamera {
    /// The orbit that sees what `camera` sees.
    pub fn from_camera(camera: Camera) -> Self {
        let offset = camera.eye - camera.target;
        let distance = offset.length().max(1e-6);
        let direction = offset / distance;
        Self {
            target: camera.target,
            yaw: direction.x.atan2(direction.z),
            pitch: direction
                .y
                .clamp(-1.0, 1.0)
                .asin()
                .clamp(-PITCH_LIMIT, PITCH_LIMIT),
            distance,
            fov_y_degrees: camera.fov_y_degrees,
        }
    }

    /// The camera at this orbit.
    pub fn camera(&self) -> Camera {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let direction = Vec3::new(sy * cp, sp, cy * cp);
        Camera {
            eye: self.target + direction * self.distance,
            target: self.target,
            fov_y_degrees: self.fov_y_degrees,
        }
    }

    /// Turns by `yaw` and `pitch` radians (positive: the camera moves
    /// right and up around the target).
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        self.yaw = (self.yaw + yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves the target (and the eye with it) by `right` and `up`, in
    /// fractions of the view's height at the target's distance, so a drag
    /// across the whole window moves the scene with the pointer.
    pub fn pan(&mut self, right: f32, up: f32) {
        let camera = self.camera();
        let forward = (camera.target - camera.eye).normalize();
        let side = forward.cross(Vec3::Y).normalize_or_zero();
        let above = side.cross(forward);
        let height = 2.0 * self.distance * (0.5 * self.fov_y_degrees).to_radians().tan();
        self.target += (side * right + above * up) * height;
    }

    /// Moves in (`factor < 1`) or out (`> 1`), never through the target.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).max(1e-5);
        }
    }

    /// The ray through a point of the view, in normalised device
    /// coordinates (x and y in −1..1, y up): origin at the eye and a unit
    /// direction.
    pub fn ray(&self, ndc_x: f32, ndc_y: f32, aspect: f32) -> (Vec3, Vec3) {
        let camera = self.camera();
        let forward = (camera.target - camera.eye).normalize();
        let side = forward.cross(Vec3::Y).normalize_or_zero();
        let above = side.cross(forward);
        let tan_y = (0.5 * self.fov_y_degrees).to_radians().tan();
        let direction = forward + side * (ndc_x * tan_y * aspect) + above * (ndc_y * tan_y);
        (camera.eye, direction.normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_orbit_reproduces_the_camera_it_was_made_from() {
        let camera = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(0.5, 0.0, -1.0),
            fov_y_degrees: 40.0,
        };
        let back = OrbitCamera::from_camera(camera).camera();
        assert!((back.eye - camera.eye).length() < 1e-5, "{back:?}");
        assert_eq!(back.target, camera.target);
    }

    #[test]
    fn orbiting_keeps_the_distance_and_stops_short_of_the_pole() {
        let mut orbit = OrbitCamera::from_camera(Camera::framing(-Vec3::ONE, Vec3::ONE, 1.5));
        let d = orbit.distance;
        orbit.orbit(1.0, 10.0);
        let camera = orbit.camera();
        assert!(((camera.eye - camera.target).length() - d).abs() < 1e-4);
        assert!(orbit.pitch < 1.56 && camera.eye.y > 0.0);
        orbit.zoom(0.5);
        assert!((orbit.distance - 0.5 * d).abs() < 1e-5);
        orbit.zoom(-1.0);
        assert!(
            (orbit.distance - 0.5 * d).abs() < 1e-5,
            "nonsense factors ignored"
        );
    }

    #[test]
    fn the_ray_through_a_pixel_lands_where_the_projection_puts_it() {
        let orbit = OrbitCamera::from_camera(Camera::framing(-Vec3::ONE, Vec3::ONE, 1.5));
        let clip = orbit.camera().clip_from_world(1.5, 2.0);
        for (x, y) in [(0.0, 0.0), (0.5, -0.3), (-0.9, 0.8)] {
            let (origin, direction) = orbit.ray(x, y, 1.5);
            let p = clip.project_point3(origin + direction * orbit.distance);
            assert!(
                (p.x - x).abs() < 1e-4 && (p.y - y).abs() < 1e-4,
                "{p} for {x},{y}"
            );
        }
    }

    #[test]
    fn panning_a_full_view_height_moves_the_target_by_that_height() {
        let mut orbit = OrbitCamera::from_camera(Camera::framing(-Vec3::ONE, Vec3::ONE, 1.0));
        let before = orbit.target;
        orbit.pan(0.0, 1.0);
        let height = 2.0 * orbit.distance * (0.5 * orbit.fov_y_degrees).to_radians().tan();
        assert!(((orbit.target - before).length() - height).abs() < 1e-4);
        let clip = orbit.camera().clip_from_world(1.0, 2.0);
        // The old target now sits a full view height below the centre.
        assert!((clip.project_point3(before).y + 2.0).abs() < 1e-3);
    }
}
