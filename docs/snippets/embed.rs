# fn host(gl: &glow::Context, cloud: &splatgl::SplatCloud, view: glam::Mat4, projection: glam::Mat4,
#         viewport: [i32; 4]) -> Result<(), splatgl::gl::GlError> {
let mut splats = splatgl::gl::SplatRenderer::new(gl)?; // once, with the host's context current
splats.upload(gl, cloud)?;                             // once: the splats → GPU textures
splats.draw_frame(gl, view, projection, viewport)?;    // per frame: cull, sort, draw
splats.destroy(gl);                                    // with the context current, at the end
# Ok(()) }
