//! Structs shared with WGSL, declared once with [`gpu_struct!`]: a
//! `#[repr(C)]` Pod struct with named fields, and `FIELDS`, each field's
//! name and byte offset. A test reflects every WGSL struct with naga and
//! checks its size, member names and offsets against these, so a field
//! added, renamed or moved on one side only fails the build's tests
//! instead of drawing garbage.
//!
//! WGSL's layout rules are met by construction here: every `[f32; 3]`
//! (a `vec3<f32>`, 16-byte aligned in WGSL) starts at a multiple of 16 and
//! is followed by a 4-byte scalar; structs are padded by named `pad`
//! members to a multiple of 16 bytes.

/// Declares a struct shared with a WGSL struct of the same fields (see the
/// module docs).
macro_rules! gpu_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$field_meta:meta])* $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $( $(#[$field_meta])* pub $field: $ty ),*
        }

        impl $name {
            /// Each field's name and byte offset, in declaration order.
            #[allow(dead_code, reason = "read by the layout test")]
            pub const FIELDS: &'static [(&'static str, usize)] = &[
                $( (stringify!($field), std::mem::offset_of!($name, $field)) ),*
            ];
        }
    };
}

pub(crate) use gpu_struct;

#[cfg(test)]
mod tests {
    use crate::dynamics::StepUniform;
    use crate::renderer::FrameUniforms;
    use crate::shells::ShellUniforms;

    /// The size and `(member, offset)` list of the struct `name` in `wgsl`,
    /// as naga lays it out.
    fn reflect(wgsl: &str, name: &str) -> (usize, Vec<(String, usize)>) {
        let module = naga::front::wgsl::parse_str(wgsl).expect("the shader parses");
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name} in the shader"));
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("{name} is not a struct");
        };
        let fields = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .collect();
        (*span as usize, fields)
    }

    fn check(shader: &str, wgsl_name: &str, size: usize, fields: &[(&str, usize)]) {
        let (wgsl_size, wgsl_fields) = reflect(crate::shader_source(shader), wgsl_name);
        let rust: Vec<(String, usize)> = fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
        assert_eq!(
            rust, wgsl_fields,
            "{shader}: struct {wgsl_name}: Rust fields (left) and WGSL members (right) differ"
        );
        assert_eq!(size, wgsl_size, "{shader}: struct {wgsl_name}: size");
    }

    #[test]
    fn rust_uniform_structs_match_their_wgsl_structs() {
        let frame = std::mem::size_of::<FrameUniforms>();
        for shader in ["mesh.wgsl", "points.wgsl", "curves.wgsl"] {
            check(shader, "Frame", frame, FrameUniforms::FIELDS);
        }
        let shell = std::mem::size_of::<ShellUniforms>();
        check("shells.wgsl", "Shell", shell, ShellUniforms::FIELDS);
        let step = std::mem::size_of::<StepUniform>();
        check("dynamics.wgsl", "Step", step, StepUniform::FIELDS);
    }

    #[test]
    fn a_moved_field_is_caught() {
        // The check itself: the Shell block with two fields swapped on the
        // Rust side must not pass.
        let mut swapped: Vec<(&str, usize)> = ShellUniforms::FIELDS.to_vec();
        let (a, b) = (swapped[1].1, swapped[2].1);
        swapped[1].1 = b;
        swapped[2].1 = a;
        let size = std::mem::size_of::<ShellUniforms>();
        let caught = std::panic::catch_unwind(|| check("shells.wgsl", "Shell", size, &swapped));
        assert!(caught.is_err());
    }
}
