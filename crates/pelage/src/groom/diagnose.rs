//! When a hair grows values that are not finite numbers (an operator's
//! settings took it past `f32`'s range), the hair is grown again one
//! operator at a time to name the operator, and its place in the groom
//! file, that took it there.

use super::error::{GroomError, GroomErrorKind};
use super::generator::Generator;
use super::grow::Workspace;
use super::ops::Hair;
use crate::mesh::SurfacePoint;

impl Generator {
    /// Hair `id`, grown from `root`, has a value that is not finite: grows
    /// it again one operator at a time to say which operator (its place in
    /// the groom file) took it there, and what went.
    pub(super) fn non_finite_error(&self, root: SurfacePoint, id: u64) -> GroomError {
        let mut ws = Workspace::default();
        let context = self.root_context(root);
        let hair = ws.batch.reset();
        self.interpolated(&context, id, &mut ws.interpolation, &mut ws.shape, hair);
        // The setting of operator `k` of the chain (the finishing ones
        // first): its line comes from the groom's origin, if it has one.
        let place = |k: usize| -> String {
            match k.checked_sub(self.base.len()) {
                Some(op) => format!("ops[{op}].{}", self.ops[op].name()),
                None => format!("finish.{}", self.base[k].name()),
            }
        };
        let error = |key: String, what: String| self.error(&key, GroomErrorKind::NotFinite(what));
        for (k, op) in self.base.iter().chain(&self.ops).enumerate() {
            op.apply(&mut ws.batch, &context, &mut ws.scratch);
            if let Some(what) = ws.batch.hairs().iter().find_map(Hair::non_finite) {
                return error(
                    place(k),
                    format!(
                        "hair {id}'s {what} are no longer finite numbers after this operator: \
                         its values take the hair past the range of 32-bit floats (about \
                         ±3.4e38); make them smaller"
                    ),
                );
            }
            if ws.batch.is_empty() {
                break;
            }
        }
        // The values are finite, the normals are not: differences of
        // points near the float range overflow.
        let farthest = ws
            .batch
            .hairs()
            .iter()
            .flat_map(|h| h.points.iter())
            .map(|p| p.abs().max_element())
            .fold(0.0f32, f32::max);
        error(
            "finish.normals".to_string(),
            format!(
                "hair {id}'s normals are not finite numbers: its points reach {farthest:e}, \
                 too far for their differences to fit in 32-bit floats; make the \
                 operators' values smaller (or set normals = false)"
            ),
        )
    }
}
