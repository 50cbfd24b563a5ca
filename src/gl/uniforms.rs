//! The splat programs' uniforms: their locations, the model matrices of a scene, and the one
//! place that sets them for a draw.

use glam::{DMat3, Mat4};
use glow::HasContext;

use super::SplatScene;
use super::program;
use super::renderer::SplatRenderer;
use super::settings::DrawSettings;
use super::view::ViewParams;

/// Declares `Uniforms`, one location per uniform the renderer sets, each field named exactly
/// like its GLSL uniform (so the two cannot get out of step).
macro_rules! uniforms {
    ($($name:ident),* $(,)?) => {
        /// The locations of the uniforms the renderer sets.
        #[derive(Debug)]
        pub(super) struct Uniforms {
            $(pub(super) $name: Option<glow::UniformLocation>,)*
        }

        impl Uniforms {
            /// Looks them up; for the correct program (`check`), a debug build asserts that
            /// they all exist.
            pub(super) fn new(gl: &glow::Context, program: glow::Program, check: bool) -> Self {
                let names = [$(stringify!($name)),*];
                let [$($name),*] = program::uniform_locations(gl, program, "splat", names, check);
                Uniforms { $($name),* }
            }
        }
    };
}

uniforms! {
    u_geometry, u_sh, u_sh_texels, u_sh_fetch_texels, u_sh_degree, u_view_matrix,
    u_projection_matrix, u_focal_length, u_tan_half_fov, u_camera_position, u_viewport,
    u_cull_depth, u_splat_count, u_model_count, u_model_rows, u_sh_rotation,
    u_antialiased,
}

/// The model matrices of the uploaded clouds, as the shader reads them: rows 0..2 of each
/// affine matrix and the transposed polar rotation (world → model directions, for the SH).
/// `count == 0`: every model is the identity (the shader skips the transform).
#[derive(Debug, Clone)]
pub(super) struct Models {
    pub(super) rows: [[f32; 12]; SplatScene::MAX_CLOUDS],
    pub(super) sh_rotation: [[f32; 9]; SplatScene::MAX_CLOUDS],
    pub(super) count: usize,
}

impl Models {
    pub(super) const IDENTITY: Models = Models {
        rows: [[0.0; 12]; SplatScene::MAX_CLOUDS],
        sh_rotation: [[0.0; 9]; SplatScene::MAX_CLOUDS],
        count: 0,
    };

    /// The uniforms for `models` (finite affine matrices, at most `MAX_CLOUDS`).
    pub(super) fn set(&mut self, models: &[Mat4]) {
        if models.iter().all(|m| *m == Mat4::IDENTITY) {
            self.count = 0;
            return;
        }
        for (k, m) in models.iter().enumerate() {
            let rows = [m.row(0), m.row(1), m.row(2)];
            for (r, row) in rows.iter().enumerate() {
                self.rows[k][4 * r..4 * r + 4].copy_from_slice(&row.to_array());
            }
            // The loader's SH rotation: the polar factor of the 3×3 (identity when singular).
            let linear = DMat3::from_mat4(m.as_dmat4());
            let r = crate::covariance::polar_rotation(linear).unwrap_or(DMat3::IDENTITY);
            self.sh_rotation[k] = r.transpose().as_mat3().to_cols_array();
        }
        self.count = models.len();
    }
}

impl SplatRenderer {
    /// Every uniform of one draw, in one place, for the program `u` belongs to (bound).
    pub(super) fn set_uniforms(
        &self,
        gl: &glow::Context,
        u: &Uniforms,
        view: &ViewParams,
        settings: &DrawSettings,
    ) {
        let tex = self.textures.as_ref().expect("checked by draw_view");
        let degree = settings
            .sh_degree
            .unwrap_or(self.cloud_degree)
            .min(self.cloud_degree);
        let [vx, vy, vw, vh] = view.viewport.map(|v| v as f32);
        let m = &self.models;
        // SAFETY: sets uniforms of the bound splat program with values of the declared types;
        // the model arrays hold MAX_CLOUDS entries, as declared.
        unsafe {
            let mat = |l, m: &Mat4| gl.uniform_matrix_4_f32_slice(l, false, &m.to_cols_array());
            mat(u.u_view_matrix.as_ref(), &view.view);
            mat(u.u_projection_matrix.as_ref(), &view.projection);
            let (f, t, e) = (view.focal, view.tan_half_fov, view.eye);
            gl.uniform_2_f32(u.u_focal_length.as_ref(), f.x, f.y);
            gl.uniform_2_f32(u.u_tan_half_fov.as_ref(), t.x, t.y);
            gl.uniform_3_f32(u.u_camera_position.as_ref(), e.x, e.y, e.z);
            gl.uniform_4_f32(u.u_viewport.as_ref(), vx, vy, vw, vh);
            gl.uniform_1_f32(u.u_cull_depth.as_ref(), view.cull_depth);
            gl.uniform_1_i32(u.u_sh_degree.as_ref(), i32::from(degree));
            gl.uniform_1_i32(u.u_sh_texels.as_ref(), tex.sh_texels as i32);
            let fetch = crate::profile::sh_texels(degree);
            gl.uniform_1_i32(u.u_sh_fetch_texels.as_ref(), fetch as i32);
            gl.uniform_1_i32(u.u_splat_count.as_ref(), tex.len as i32);
            gl.uniform_1_i32(u.u_geometry.as_ref(), 0);
            gl.uniform_1_i32(u.u_sh.as_ref(), 1);
            gl.uniform_1_i32(u.u_model_count.as_ref(), m.count as i32);
            let aa = i32::from(settings.antialiased);
            gl.uniform_1_i32(u.u_antialiased.as_ref(), aa);
            if m.count > 0 {
                let rows = bytemuck::cast_slice(&m.rows[..m.count]);
                gl.uniform_4_f32_slice(u.u_model_rows.as_ref(), rows);
                let sh = bytemuck::cast_slice(&m.sh_rotation[..m.count]);
                gl.uniform_matrix_3_f32_slice(u.u_sh_rotation.as_ref(), false, sh);
            }
        }
    }
}
