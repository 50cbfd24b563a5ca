//! The legacy (compatibility-profile) GL entry points `glow` does not load — fixed-function
//! matrices, immediate mode, client arrays, texture environment, `glLogicOp` — as a small
//! table of `extern "system"` function pointers loaded through the context's
//! `get_proc_address` (here `HeadlessContext::get_proc_address`; a windowed host would use
//! glutin's). No binding crate needed.
#![allow(dead_code)]

use std::ffi::c_void;

type Enum = u32;

/// `GL_MODELVIEW`, `GL_PROJECTION`, `GL_TEXTURE` matrix modes.
pub const MODELVIEW: Enum = 0x1700;
pub const PROJECTION: Enum = 0x1701;
pub const TEXTURE: Enum = 0x1702;
pub const MATRIX_MODE: Enum = 0x0BA0;
pub const MODELVIEW_MATRIX: Enum = 0x0BA6;
pub const PROJECTION_MATRIX: Enum = 0x0BA7;
pub const TEXTURE_MATRIX: Enum = 0x0BA8;
/// `glBegin` modes.
pub const QUADS: Enum = 0x0007;
pub const TRIANGLES: Enum = 0x0004;
/// Client arrays.
pub const VERTEX_ARRAY: Enum = 0x8074;
pub const COLOR_ARRAY: Enum = 0x8076;
pub const TEXTURE_COORD_ARRAY: Enum = 0x8078;
pub const VERTEX_ARRAY_SIZE: Enum = 0x807A;
pub const VERTEX_ARRAY_STRIDE: Enum = 0x807C;
pub const VERTEX_ARRAY_BUFFER_BINDING: Enum = 0x8896;
pub const CLIENT_ACTIVE_TEXTURE: Enum = 0x84E1;
/// Current values.
pub const CURRENT_COLOR: Enum = 0x0B00;
pub const CURRENT_NORMAL: Enum = 0x0B02;
pub const CURRENT_TEXTURE_COORDS: Enum = 0x0B03;
/// Fixed-function capabilities and state.
pub const LIGHTING: Enum = 0x0B50;
pub const FOG: Enum = 0x0B60;
pub const NORMALIZE: Enum = 0x0BA1;
pub const COLOR_MATERIAL: Enum = 0x0B57;
pub const LINE_STIPPLE: Enum = 0x0B24;
pub const ALPHA_TEST: Enum = 0x0BC0;
pub const ALPHA_TEST_FUNC: Enum = 0x0BC1;
pub const ALPHA_TEST_REF: Enum = 0x0BC2;
pub const SHADE_MODEL: Enum = 0x0B54;
pub const FLAT: Enum = 0x1D00;
pub const SMOOTH: Enum = 0x1D01;
pub const TEXTURE_ENV: Enum = 0x2300;
pub const TEXTURE_ENV_MODE: Enum = 0x2200;
pub const MODULATE: Enum = 0x2100;
pub const DECAL: Enum = 0x2101;
pub const LOGIC_OP_MODE: Enum = 0x0BF0;
pub const XOR: Enum = 0x1506;
pub const POINT_SIZE: Enum = 0x0B11;

macro_rules! legacy_gl {
    ($($field:ident: $name:literal fn($($arg:ty),*);)*) => {
        /// The entry points, loaded once per context.
        #[allow(non_snake_case)]
        pub struct LegacyGl {
            $(pub $field: unsafe extern "system" fn($($arg),*),)*
        }

        impl LegacyGl {
            /// Loads every entry point; `Err` names the first one the driver lacks.
            pub fn load(get: impl Fn(&str) -> *const c_void) -> Result<Self, String> {
                Ok(LegacyGl {
                    $($field: {
                        let p = get($name);
                        if p.is_null() {
                            return Err(format!("{} is not available", $name));
                        }
                        // SAFETY: the driver returned the entry point of this name, whose C
                        // signature is the one declared here.
                        unsafe { std::mem::transmute::<*const c_void, unsafe extern "system" fn($($arg),*)>(p) }
                    },)*
                })
            }
        }
    };
}

legacy_gl! {
    matrix_mode: "glMatrixMode" fn(Enum);
    load_matrix: "glLoadMatrixf" fn(*const f32);
    load_identity: "glLoadIdentity" fn();
    begin: "glBegin" fn(Enum);
    end: "glEnd" fn();
    vertex3: "glVertex3f" fn(f32, f32, f32);
    tex_coord2: "glTexCoord2f" fn(f32, f32);
    color4: "glColor4f" fn(f32, f32, f32, f32);
    normal3: "glNormal3f" fn(f32, f32, f32);
    enable_client_state: "glEnableClientState" fn(Enum);
    disable_client_state: "glDisableClientState" fn(Enum);
    vertex_pointer: "glVertexPointer" fn(i32, Enum, i32, *const c_void);
    color_pointer: "glColorPointer" fn(i32, Enum, i32, *const c_void);
    tex_coord_pointer: "glTexCoordPointer" fn(i32, Enum, i32, *const c_void);
    client_active_texture: "glClientActiveTexture" fn(Enum);
    tex_envi: "glTexEnvi" fn(Enum, Enum, i32);
    get_tex_enviv: "glGetTexEnviv" fn(Enum, Enum, *mut i32);
    shade_model: "glShadeModel" fn(Enum);
    alpha_func: "glAlphaFunc" fn(Enum, f32);
    logic_op: "glLogicOp" fn(Enum);
    point_size: "glPointSize" fn(f32);
    draw_arrays: "glDrawArrays" fn(Enum, i32, i32);
}
