//! RPI's textures: `vt s t`, which gives texture coordinates to the last vertex read, and a
//! material's `texture_file NAME`, a PPM read from the scene file's folder (`scene::texture`).

use super::{ParseError, Parser};
use crate::render::quote::quote;
use crate::render::scene::texture_file::{read_texture, resolve};
use glam::Vec3;

impl Parser<'_> {
    /// `vt s [t [w]]`: the coordinates of the vertex just read. A missing t is 0 and a w is
    /// ignored, as in OBJ; each number must be finite.
    pub(super) fn texture_coords(&mut self, line: usize, args: &[&str]) -> Result<(), ParseError> {
        if self.vertex_st.is_empty() {
            return Err(self.error(
                line,
                "expected a `v` line before `vt` (its coordinates belong to the vertex just read), \
                 found `vt` before any vertex",
            ));
        }
        let s = self.number(line, "the s coordinate of `vt`", args.first().copied())?;
        let t = match args.get(1) {
            Some(token) => self.number(line, "the t coordinate of `vt`", Some(token))?,
            None => 0.0,
        };
        if let Some(w) = args.get(2) {
            self.number(line, "the w coordinate of `vt`", Some(w))?;
        }
        self.no_more(line, "vt", args, 3)?;
        *self.vertex_st.last_mut().expect("checked non-empty") = Some([s, t]);
        Ok(())
    }

    /// `texture_file NAME`: the current material's diffuse colour comes from the texture. It is
    /// read now, so that its errors name this line.
    pub(super) fn texture_file(&mut self, line: usize, args: &[&str]) -> Result<(), ParseError> {
        let Some(&name) = args.first() else {
            return Err(self.error(
                line,
                "expected a file name after `texture_file`, found the end of the line",
            ));
        };
        self.no_more(line, "texture_file", args, 1)?;
        let had_diffuse = self.current_material(line, "texture_file")?.diffuse != Vec3::ZERO;
        let (path, outside) = resolve(name, self.base);
        let index = match self.textures.iter().position(|t| t.path == path) {
            Some(i) => i,
            None => {
                let mut texture = read_texture(name, &path).map_err(|e| {
                    self.error(line, format!("texture_file `{}`: {e}", quote(name)))
                })?;
                texture.outside_folder = outside;
                self.textures.push(texture);
                self.textures.len() - 1
            }
        };
        let average = self.textures[index].average;
        let material = self.current_material(line, "texture_file")?;
        material.texture = Some(index as u32);
        material.diffuse = average;
        if had_diffuse {
            self.warn(
                line,
                "the texture replaces the `diffuse` colour given above (RPI's materials have one \
                 or the other)",
            );
        }
        Ok(())
    }
}
