//! A light cut: a light whose emitted power jumps between two frames (switched on or off, or
//! changed by more than [`LIGHT_CUT_RATIO`]) restarts the indirect light's histories, so the
//! light it took away is gone at once instead of fading out of the history over frames
//! (issue 43: IGI kept 7.5 % of a switched-off spot for a frame and needed 5 to drop below
//! 5 %; docs/quality.md). The frame's lights are known on the CPU, so no pixel has to guess.

use shine_scene::Light;

/// The factor by which a light's emitted power (intensity × its colour's largest channel)
/// must grow or shrink between frames to restart the histories. 2: a dimmer or a flicker
/// that stays within a factor of two blends through the history as before (its change is
/// what the neighbourhood clip and the restart on a large pixel change already follow); a
/// switch, or a jump the history would trail, restarts.
pub const LIGHT_CUT_RATIO: f32 = 2.0;

/// The power a light emits, up to a constant: what a cut compares.
fn power(light: &Light) -> f32 {
    let colour = light.color.iter().copied().fold(0.0f32, f32::max);
    (light.intensity * colour).max(0.0)
}

/// Whether going from `before` to `after` (the same lights, in order) is a light cut: a light
/// switched on or off, or whose power changed by more than [`LIGHT_CUT_RATIO`]; a light list
/// of another length is one too.
pub fn is_light_cut(before: &[Light], after: &[Light]) -> bool {
    if before.len() != after.len() {
        return true;
    }
    before.iter().zip(after).any(|(a, b)| {
        let (a, b) = (power(a), power(b));
        let (low, high) = (a.min(b), a.max(b));
        match (low > 0.0, high > 0.0) {
            (false, false) => false,
            (false, true) => true,
            _ => high > LIGHT_CUT_RATIO * low,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(intensity: f32) -> Light {
        Light {
            intensity,
            color: [1.0, 0.5, 0.25],
            ..bytemuck::Zeroable::zeroed()
        }
    }

    #[test]
    fn switches_and_large_jumps_cut_and_small_changes_do_not() {
        let lit = [light(10.0), light(3.0)];
        let cases = [
            ([light(10.0), light(3.0)], false),
            ([light(15.0), light(3.0)], false),
            ([light(10.0), light(1.6)], false),
            ([light(10.0), light(0.0)], true),
            ([light(25.0), light(3.0)], true),
            ([light(4.0), light(3.0)], true),
        ];
        for (after, cut) in cases {
            assert_eq!(is_light_cut(&lit, &after), cut, "{after:?}");
        }
        assert!(is_light_cut(&lit, &lit[..1]));
        assert!(!is_light_cut(&[light(0.0)], &[light(0.0)]));
        assert!(is_light_cut(&[light(0.0)], &[light(1.0)]));
    }
}
