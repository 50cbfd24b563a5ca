//! The paged storage of streamed tilesets: pages of [`PAGE_SPLATS`] slots, written one tile
//! at a time ([`SplatRenderer::write_page`]).

use super::*;

impl SplatRenderer {
    /// Allocates paged storage: `pages` pages of [`PAGE_SPLATS`] splat slots each, for clouds
    /// of SH degree up to `sh_degree`, drawn in `color_space` (replaces any cloud or pages;
    /// the slots' contents are undefined until written). For streamed tilesets: each tile
    /// goes into pages of its own ([`SplatRenderer::write_page`]), loading or evicting one never
    /// re-uploads the others, and [`SplatRenderer::set_order`] takes slot indices
    /// (`page · PAGE_SPLATS + i`). GL state as [`SplatRenderer::upload`]; on failure the previous
    /// storage stays.
    pub fn allocate_pages(
        &mut self,
        gl: &glow::Context,
        pages: usize,
        sh_degree: u8,
        color_space: ColorSpace,
    ) -> Result<(), GlError> {
        self.owned.check()?;
        let n = pages.saturating_mul(PAGE_SPLATS);
        let errors = ErrorScope::begin(gl)?;
        let host = Bindings::for_upload(gl, self.ctx);
        let mut textures = SplatTextures::allocate(gl, n, sh_degree.min(3), &self.layout)?;
        drop(host);
        if let Err(e) = errors.end("allocating splat pages") {
            textures.destroy(gl);
            return Err(e);
        }
        self.replace_textures(gl, textures, color_space)?;
        self.models = Models::IDENTITY;
        self.paged = true;
        Ok(())
    }

    /// Writes splats `first .. first + PAGE_SPLATS` of `cloud` (fewer at its end) into page
    /// `page` of the storage [`SplatRenderer::allocate_pages`] made. Errors: no pages
    /// ([`GlError::NotUploaded`]), a page or range outside them or a cloud of a higher SH
    /// degree than the storage ([`GlError::Upload`]), GL errors. GL state as
    /// [`SplatRenderer::upload`].
    pub fn write_page(
        &mut self,
        gl: &glow::Context,
        page: usize,
        cloud: &SplatCloud,
        first: usize,
    ) -> Result<(), GlError> {
        self.owned.check()?;
        let Some(textures) = &self.textures else {
            return Err(GlError::NotUploaded);
        };
        let count = cloud.len().saturating_sub(first).min(PAGE_SPLATS);
        if (page + 1).saturating_mul(PAGE_SPLATS) > textures.len || first > cloud.len() {
            return Err(GlError::Upload(format!(
                "page {page} (splats {first}.. of {}) is outside the {} pages allocated",
                cloud.len(),
                textures.len / PAGE_SPLATS
            )));
        }
        if cloud.sh_degree > textures.sh_degree {
            return Err(GlError::Upload(format!(
                "a cloud of SH degree {} does not fit pages of degree {}",
                cloud.sh_degree, textures.sh_degree
            )));
        }
        let clouds = [cloud];
        let set = CloudSet::new(&clouds)?;
        let errors = ErrorScope::begin(gl)?;
        let host = Bindings::for_upload(gl, self.ctx);
        textures.write(
            gl,
            &self.layout,
            page * PAGE_SPLATS,
            &set,
            first..first + count,
        );
        drop(host);
        errors.end("writing a splat page")
    }

    /// Pages allocated by [`SplatRenderer::allocate_pages`] (0 after a plain upload).
    pub fn pages(&self) -> usize {
        match &self.textures {
            Some(t) if self.paged => t.len / PAGE_SPLATS,
            _ => 0,
        }
    }
}
