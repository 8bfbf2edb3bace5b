//! Buttons wired to a Haply board's analog pins: the device file's `[[buttons]]` tables, their
//! place in the board set-up, and the per-exchange reading behind
//! [`DeviceIo::buttons`](haptic2d_rt::DeviceIo::buttons).
//!
//! ```toml
//! [[buttons]]            # button 0 (the first table), then button 1, …; at most 8
//! pin = "A2"             # an analog pin A0–A11, or its number 54–65
//! pressed_above = 512.0  # pressed while the pin reads above this (the board's ADC units)
//! ```
//!
//! The board reports each analog pin of the set-up as a float in every reply (docs/DEVICES.md §1):
//! the ADC reading, in the board's units (haptic2d's firmware sends `analogRead(pin)` as is; on the
//! Arduino cores of the M0/M3 boards, with no resolution set, that is 10 bits, 0–1023 over
//! 0–3.3 V; the stock firmware's scale is *verify*). The readings come in **ascending pin order**
//! whatever order the set-up lists the pins in (DEVICES §1.3 rule 7), so a button is found in a
//! reply by its pin's rank among the button pins, never by its place in the file.
//!
//! Debounce: a button's reported state changes only when **two consecutive samples** agree on the
//! new state (one exchange of delay, 1 ms at 1 kHz); a single sample across the threshold (a bounce,
//! a noise spike) changes nothing. No hysteresis beyond that.

use haptic2d::scene::SceneError;
use serde::Deserialize;

use super::codec::{BoardSetup, ANALOG_PIN_MAX, ANALOG_PIN_MIN, MAX_SENSORS};

/// Most buttons a device file may name (the bits of [`DeviceIo::buttons`](haptic2d_rt::DeviceIo::buttons)).
pub const MAX_BUTTONS: usize = 8;

/// One `[[buttons]]` table as written.
#[derive(Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawButton {
    pin: RawPin,
    pressed_above: f64,
}

/// A pin as written: `"A2"` or `56`.
#[derive(Deserialize, Clone, Debug)]
#[serde(untagged)]
enum RawPin {
    Name(String),
    Number(i64),
}

/// A button on an analog pin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ButtonSpec {
    /// The analog pin (54–65 = A0–A11).
    pub pin: u8,
    /// The button is pressed while the pin reads above this (the board's ADC units, e.g. counts
    /// 0–1023).
    pub pressed_above: f64,
}

/// The pin number of `A0`–`A11` (case-insensitive) or of a number 54–65; `None` otherwise.
fn pin_number(p: &RawPin) -> Option<u8> {
    let n = match p {
        RawPin::Name(s) => {
            let rest = s.trim().strip_prefix(['A', 'a'])?;
            let i: u8 = rest.parse().ok()?;
            ANALOG_PIN_MIN.checked_add(i)?
        }
        RawPin::Number(n) => u8::try_from(*n).ok()?,
    };
    (ANALOG_PIN_MIN..=ANALOG_PIN_MAX).contains(&n).then_some(n)
}

/// Checks the `[[buttons]]` tables (pins A0–A11, at most [`MAX_BUTTONS`], no pin twice, a finite
/// threshold), pushing one error per problem with the field and the fix; returns the buttons in
/// file order (button `i` = the `i`-th table).
pub(crate) fn check(raw: &[RawButton], errs: &mut Vec<SceneError>) -> Vec<ButtonSpec> {
    if raw.len() > MAX_BUTTONS {
        errs.push(SceneError::new(
            "buttons",
            format!("{} [[buttons]] tables, at most {MAX_BUTTONS}", raw.len()),
            "keep at most 8 buttons (bits 0–7 of a device's buttons)",
        ));
    }
    let mut out: Vec<ButtonSpec> = Vec::new();
    for (i, b) in raw.iter().enumerate() {
        let f = format!("buttons[{i}]");
        let pin = pin_number(&b.pin);
        match pin {
            None => errs.push(SceneError::new(
                format!("{f}.pin"),
                match &b.pin {
                    RawPin::Name(s) => format!("`{s}` is not an analog pin"),
                    RawPin::Number(n) => format!("{n} is not an analog pin number"),
                },
                "write an analog pin \"A0\" … \"A11\", or its number 54–65",
            )),
            Some(p) if out.iter().any(|o| o.pin == p) => errs.push(SceneError::new(
                format!("{f}.pin"),
                format!("pin A{} is already button {}", p - ANALOG_PIN_MIN, {
                    out.iter().position(|o| o.pin == p).unwrap_or(0)
                }),
                "wire each button to its own analog pin",
            )),
            Some(_) => {}
        }
        if !b.pressed_above.is_finite() {
            errs.push(SceneError::new(
                format!("{f}.pressed_above"),
                format!("{} is not a finite number", b.pressed_above),
                "give the analog reading (the board's ADC units, 0–1023 on a 10-bit ADC) above which the button counts as pressed, e.g. 512",
            ));
        }
        out.push(ButtonSpec {
            pin: pin.unwrap_or(0),
            pressed_above: b.pressed_above,
        });
    }
    out
}

/// Adds the buttons' pins to `setup`'s analog sensors, in file order (the board reports them in
/// ascending pin order whatever the order here).
pub fn add_to_setup(buttons: &[ButtonSpec], setup: &mut BoardSetup) {
    let n = buttons.len().min(MAX_BUTTONS).min(MAX_SENSORS);
    for (slot, b) in setup.sensor_pins.iter_mut().zip(&buttons[..n]) {
        *slot = b.pin;
    }
    setup.n_sensors = n as u8;
}

/// The buttons' state from the replies' analog values, debounced over two samples. No allocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ButtonReader {
    n: usize,
    /// Where button `i`'s reading is in a reply: its pin's rank among the button pins.
    slot: [usize; MAX_BUTTONS],
    /// Button `i` is pressed while its reading exceeds `threshold[i]`.
    threshold: [f64; MAX_BUTTONS],
    /// The previous sample's raw (undebounced) bits.
    last_raw: u8,
    /// The debounced state (bit `i` = button `i`).
    state: u8,
}

impl ButtonReader {
    /// A reader for `buttons` (file order; at most [`MAX_BUTTONS`] are read), all released.
    pub fn new(buttons: &[ButtonSpec]) -> Self {
        let n = buttons.len().min(MAX_BUTTONS);
        let mut slot = [0; MAX_BUTTONS];
        let mut threshold = [0.0; MAX_BUTTONS];
        for (i, b) in buttons[..n].iter().enumerate() {
            slot[i] = buttons[..n].iter().filter(|o| o.pin < b.pin).count();
            threshold[i] = b.pressed_above;
        }
        Self {
            n,
            slot,
            threshold,
            last_raw: 0,
            state: 0,
        }
    }

    /// Takes one reply's analog values (`analog[k]` = the `k`-th button pin in ascending pin
    /// order) and returns the debounced state: a button's bit changes only when this sample and
    /// the previous one agree on its new value.
    pub fn update(&mut self, analog: &[f32]) -> u8 {
        let mut raw = 0u8;
        for i in 0..self.n {
            let v = analog.get(self.slot[i]).copied().unwrap_or(0.0) as f64;
            if v > self.threshold[i] {
                raw |= 1 << i;
            }
        }
        let agree = !(raw ^ self.last_raw);
        self.state = (self.state & !agree) | (raw & agree);
        self.last_raw = raw;
        self.state
    }

    /// The debounced state (bit `i` = button `i` pressed).
    pub fn state(&self) -> u8 {
        self.state
    }

    /// Forgets every press (a lost device reports no buttons).
    pub fn clear(&mut self) {
        self.state = 0;
        self.last_raw = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(pin: u8, above: f64) -> ButtonSpec {
        ButtonSpec {
            pin,
            pressed_above: above,
        }
    }

    #[test]
    fn a_button_is_found_by_its_pins_rank_not_its_place_in_the_file() {
        // Button 0 on A5 (61), button 1 on A2 (56): the reply holds A2 first, then A5.
        let mut r = ButtonReader::new(&[spec(61, 500.0), spec(56, 500.0)]);
        // A2 pressed (first reading), twice: button 1.
        assert_eq!(r.update(&[900.0, 10.0]), 0, "one sample is not yet a press");
        assert_eq!(r.update(&[900.0, 10.0]), 0b10);
        // A5 pressed too.
        r.update(&[900.0, 900.0]);
        assert_eq!(r.update(&[900.0, 900.0]), 0b11);
    }

    #[test]
    fn a_single_sample_across_the_threshold_changes_nothing() {
        let mut r = ButtonReader::new(&[spec(54, 512.0)]);
        for v in [0.0, 1000.0, 0.0, 1000.0, 0.0] {
            assert_eq!(
                r.update(&[v]),
                0,
                "a bounce alternating each sample is no press"
            );
        }
        r.update(&[1000.0]);
        assert_eq!(r.update(&[1000.0]), 1);
        // A one-sample dip while held is no release.
        assert_eq!(r.update(&[0.0]), 1);
        assert_eq!(r.update(&[1000.0]), 1);
        r.update(&[0.0]);
        assert_eq!(r.update(&[0.0]), 0, "two samples below: released");
        // Exactly at the threshold is not above it.
        r.update(&[512.0]);
        assert_eq!(r.update(&[512.0]), 0);
    }

    #[test]
    fn the_setup_lists_the_button_pins_in_file_order() {
        let mut s = BoardSetup::empty(1);
        add_to_setup(&[spec(61, 1.0), spec(56, 1.0)], &mut s);
        assert_eq!((s.n_sensors, &s.sensor_pins[..2]), (2, &[61u8, 56][..]));
        assert!(s.validate().is_ok());
        assert_eq!(s.reply_len(), 1 + 4 * 2);
    }

    #[test]
    fn pins_are_a0_to_a11_by_name_or_number() {
        let name = |s: &str| pin_number(&RawPin::Name(s.into()));
        assert_eq!(name("A0"), Some(54));
        assert_eq!(name("a11"), Some(65));
        assert_eq!(name("A12"), None);
        assert_eq!(name("D2"), None);
        assert_eq!(name("A"), None);
        assert_eq!(pin_number(&RawPin::Number(56)), Some(56));
        assert_eq!(pin_number(&RawPin::Number(2)), None);
        assert_eq!(pin_number(&RawPin::Number(66)), None);
        assert_eq!(pin_number(&RawPin::Number(-1)), None);
    }
}
