//! A pinhole camera for the mesh renderer: right-handed look-at view (the camera looks down −z, y up) and a
//! perspective projection to wgpu's clip space (x, y ∈ [−1, 1], depth z ∈ [0, 1] from the near to the far plane).
//! Positions in mesh units (metres for glTF and the default head).

use crate::error::{check_positive, check_range, InvalidInput};
use nalgebra::{Matrix4, Point3, Vector3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Near and far planes, mesh units from the eye (> 0, near < far).
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// A camera `distance` units in front of the head (on +z), looking at the origin with a 30° vertical field
    /// of view (TAP 2009's heads: a close-up is ~0.5 m, "far" a few metres).
    pub fn facing(distance: f32) -> Result<Camera, InvalidInput> {
        check_range("distance_m", distance as f64, 0.2, 100.0, "m")?;
        Ok(Camera {
            eye: [0.0, 0.0, distance],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 30.0,
            near: 0.05,
            far: distance + 10.0,
        })
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("fov_y_deg", self.fov_y_deg as f64, 1.0, 170.0, "degrees")?;
        check_positive("near", self.near as f64, "mesh units")?;
        if !(self.far > self.near && self.far.is_finite()) {
            return Err(InvalidInput::new(
                "far",
                format!("must be finite and > near ({}), got {}", self.near, self.far),
            ));
        }
        let dir = Vector3::from(self.target) - Vector3::from(self.eye);
        if dir.norm().is_nan() || dir.norm() <= 0.0 || dir.cross(&Vector3::from(self.up)).norm() <= 1e-6 * dir.norm() {
            return Err(InvalidInput::new("camera", "eye, target and up must be finite, distinct and not collinear"));
        }
        Ok(())
    }

    /// World → view (camera at the origin looking down −z).
    pub fn view(&self) -> Matrix4<f32> {
        Matrix4::look_at_rh(&Point3::from(self.eye), &Point3::from(self.target), &Vector3::from(self.up))
    }

    /// View → clip for an image of `aspect` = width / height, depth mapped to [0, 1].
    pub fn projection(&self, aspect: f32) -> Matrix4<f32> {
        let f = 1.0 / (0.5 * self.fov_y_deg.to_radians()).tan();
        let (n, fa) = (self.near, self.far);
        #[rustfmt::skip]
        let m = Matrix4::new(
            f / aspect, 0.0, 0.0, 0.0,
            0.0, f, 0.0, 0.0,
            0.0, 0.0, fa / (n - fa), n * fa / (n - fa),
            0.0, 0.0, -1.0, 0.0,
        );
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector4;

    #[test]
    fn near_and_far_map_to_zero_and_one_and_the_target_to_the_centre() {
        let c = Camera::facing(0.6).unwrap();
        let vp = c.projection(1.5) * c.view();
        let clip = |p: [f32; 3]| {
            let v = vp * Vector4::new(p[0], p[1], p[2], 1.0);
            [v.x / v.w, v.y / v.w, v.z / v.w]
        };
        let centre = clip([0.0, 0.0, 0.0]);
        assert!(centre[0].abs() < 1e-6 && centre[1].abs() < 1e-6);
        assert!(clip([0.0, 0.0, 0.6 - c.near])[2].abs() < 1e-5);
        assert!((clip([0.0, 0.0, 0.6 - c.far])[2] - 1.0).abs() < 1e-5);
        // Half the field of view up is the top edge of the image.
        let top = clip([0.0, 0.6 * (15f32).to_radians().tan(), 0.0]);
        assert!((top[1] - 1.0).abs() < 1e-5, "{top:?}");
        assert!(Camera::facing(0.0).is_err());
    }
}
