//! The depth convention every pass follows, in one place.
//!
//! **Reversed-Z floating-point depth**: the projection maps the near plane to 1 and the far
//! plane to 0, the depth buffer is cleared to 0 ([`CLEAR`]: no geometry, "infinitely far") and
//! nearer means greater. A float's relative precision is the same at every magnitude, and
//! reversed-Z puts the many small values where the projection's 1/w compresses distance, so a
//! glTF camera with znear 10⁻⁶ and zfar 10⁶ keeps ~7 significant digits of view distance over
//! the whole range (standard-Z `Depth32Float` put pipelines that rebuild positions from depth
//! 52 levels off `forward` at znear 10⁻⁴ / zfar 10⁴, ECOSYSTEM.md). `depth = A / w - B` with
//! `A = near·far / (far - near)` and `B = near / (far - near)`; [`view_distance`] is its
//! inverse and `view_distance_from_depth` in `shading/scene_bindings.wgsl` the GPU twin.
//!
//! **One surface per pixel**: every pass that draws the scene's opaque surfaces, with or
//! without a depth pre-pass, tests [`SURFACE`] (nearer or as near): of coplanar surfaces the
//! last one drawn wins in every pipeline alike, since a pre-pass followed by an equal-depth
//! shading pass can only pick the last of the equal ones too. The vertex stage's position is
//! `@invariant`, so a pre-pass and a shading pass compute bit-identical depths.

/// What the depth buffer is cleared to: no geometry (the far plane or beyond).
pub const CLEAR: f32 = 0.0;

/// Nearer than, or as near as, what is there.
pub(crate) const NEARER_OR_EQUAL: wgpu::CompareFunction = wgpu::CompareFunction::GreaterEqual;

/// The test of every pass that draws the scene's opaque surfaces (pre-passes, G-buffers,
/// forward and post-pre-pass shading).
pub const SURFACE: wgpu::CompareFunction = NEARER_OR_EQUAL;

/// Strictly nearer than what is there (the transparent pass over the opaque depth: a
/// transparent surface coplanar with an opaque one is behind it, in every pipeline alike).
pub(crate) const NEARER: wgpu::CompareFunction = wgpu::CompareFunction::Greater;

/// Farther than, or as far as, what is there (a light volume's back faces).
pub(crate) const FARTHER_OR_EQUAL: wgpu::CompareFunction = wgpu::CompareFunction::LessEqual;

/// Does a depth-buffer value hold no geometry?
pub fn is_background(depth: f32) -> bool {
    depth <= CLEAR
}

/// The projection's depth-buffer value at view distance `w` (`w = -z` in view space).
pub fn depth_of(w: f32, near: f32, far: f32) -> f32 {
    let (a, b) = coefficients(near, far);
    a / w - b
}

/// View distance of a depth-buffer value: the inverse of [`depth_of`] (infinite for the
/// background, [`is_background`]).
pub fn view_distance(depth: f32, near: f32, far: f32) -> f32 {
    if is_background(depth) {
        return f32::INFINITY;
    }
    let (a, b) = coefficients(near, far);
    a / (depth + b)
}

/// The smallest `near / far` a camera may have: below it `B` (the depth just before the far
/// plane) nears f32's smallest normal number, which GPUs flush to zero, and a surface there
/// would read as the background. Real files stop far above it (10⁻¹² for znear 10⁻⁶ and
/// zfar 10⁶).
pub(crate) const MIN_NEAR_FAR_RATIO: f32 = 1e-30;

/// Can the depth buffer hold a camera with these planes? `0 < near < far`, both finite, and
/// `near / far` at least [`MIN_NEAR_FAR_RATIO`]: otherwise the frame is refused, never
/// rendered with depths that lost the surfaces.
pub(crate) fn check_planes(near: f32, far: f32) -> crate::error::Result<()> {
    if !(near.is_finite() && far.is_finite() && near > 0.0 && far > near) {
        return Err(crate::error::Error::invalid(
            "camera",
            format!("needs finite planes with 0 < near < far; near {near}, far {far}"),
        ));
    }
    if near / far < MIN_NEAR_FAR_RATIO {
        return Err(crate::error::Error::invalid(
            "camera",
            format!(
                "near {near} / far {far} is below {MIN_NEAR_FAR_RATIO:e}: the depth buffer \
                 cannot tell surfaces near the far plane from the background"
            ),
        ));
    }
    Ok(())
}

/// `(A, B)` of `depth = A / w - B`, computed in f64 so a tiny near plane loses nothing.
pub(crate) fn coefficients(near: f32, far: f32) -> (f32, f32) {
    let (n, f) = (f64::from(near), f64::from(far));
    ((n * f / (f - n)) as f32, (n / (f - n)) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_and_view_distance_are_inverses_over_real_camera_ranges() {
        for (near, far) in [(1e-6, 100.0), (0.05, 1e6), (1.0, 10.0), (1e-4, 1e4)] {
            assert!((depth_of(near, near, far) - 1.0).abs() < 1e-6);
            assert!(depth_of(far, near, far).abs() < 1e-6);
            let mut w = near;
            while w < far {
                let back = view_distance(depth_of(w, near, far), near, far);
                assert!(
                    (back - w).abs() <= 1e-5 * w,
                    "near {near} far {far}: w {w} came back as {back}"
                );
                w *= 3.7;
            }
        }
        assert_eq!(view_distance(CLEAR, 0.1, 100.0), f32::INFINITY);
    }

    #[test]
    fn cameras_the_depth_buffer_cannot_hold_are_refused() {
        assert!(check_planes(1e-6, 1e6).is_ok());
        assert!(check_planes(1e-20, 1e9).is_ok());
        for (near, far) in [
            (0.0, 1.0),
            (-1.0, 1.0),
            (1.0, 1.0),
            (2.0, 1.0),
            (f32::NAN, 1.0),
            (0.1, f32::INFINITY),
            (1e-30, 1e6),
        ] {
            assert!(check_planes(near, far).is_err(), "near {near} far {far}");
        }
    }

    #[test]
    fn nearer_is_greater() {
        assert!(depth_of(1.0, 0.1, 100.0) > depth_of(2.0, 0.1, 100.0));
        assert!(!is_background(depth_of(99.0, 0.1, 100.0)));
        assert!(is_background(CLEAR));
    }
}
