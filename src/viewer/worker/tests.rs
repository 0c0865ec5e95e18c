//! Tests of `worker`.

use super::*;

#[test]
fn passes_describe_what_they_dropped() {
    let preview = Preview {
        divisor: 2,
        reflections: Reflections::Off,
        shadows: true,
    };
    assert_eq!(
        PassKind::Preview(preview).label(),
        "preview 1/2, no reflections"
    );
    let one = Preview {
        reflections: Reflections::OneBounce,
        ..preview
    };
    assert_eq!(one.describe(), "1/2, one bounce");
    let bare = Preview {
        divisor: 1,
        reflections: Reflections::Off,
        shadows: false,
    };
    assert_eq!(
        bare.describe(),
        "full resolution, no reflections, no shadows"
    );
}
