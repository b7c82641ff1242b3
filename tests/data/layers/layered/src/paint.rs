//! Paint, below the brush that lays it down.

/// Paint.
pub struct Paint {
    /// Its colour.
    pub colour: [f32; 3],
}

#[cfg(test)]
mod tests {
    use crate::Brush;

    #[test]
    fn a_brush_holds_paint() {
        let brush = Brush { paint: super::Paint { colour: [1.0; 3] } };
        assert_eq!(brush.paint.colour[0], 1.0);
    }
}
