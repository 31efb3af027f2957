//! The participant's controls and the messages a page sends: parsed, bounded
//! and checked before they reach the loop ([`Inbox`]).
//!
//! Axes arrive in `[-1, 1]` and are kept as whole steps of 1/1024
//! ([`AXIS_STEPS`]), so that the record holds them exactly and a resumed session
//! replays the very same commands.

use std::time::{Duration, Instant};

use palc_harness::live::{LiveInput, LiveLimits};
use serde::{Deserialize, Serialize};

/// Steps of an axis from 0 to full deflection.
pub const AXIS_STEPS: i16 = 1024;

/// Largest message a page may send (bytes).
pub const MAX_MESSAGE_BYTES: usize = 1024;

/// Most messages a page may send in one second.
pub const MAX_MESSAGES_PER_S: usize = 120;

/// The participant's controls at a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Control {
    /// Whether the participant has taken over (it stays taken over within the
    /// lane change).
    pub take_over: bool,
    /// Steering: lateral speed as a fraction of the limit, in 1/1024 (positive
    /// to the left).
    pub lateral: i16,
    /// Speed: acceleration (positive) or braking (negative) as a fraction of
    /// the limit, in 1/1024; 0 leaves the speed to the ACC.
    pub speed: i16,
}

impl Control {
    /// The loop's input for these controls under `limits`.
    pub fn input(&self, limits: &LiveLimits) -> LiveInput {
        let fraction = |axis: i16| f64::from(axis) / f64::from(AXIS_STEPS);
        let speed = fraction(self.speed);
        LiveInput {
            take_over: self.take_over,
            lateral_speed_mps: fraction(self.lateral) * limits.max_lateral_speed_mps,
            acceleration_mps2: match self.speed {
                0 => None,
                s if s > 0 => Some(speed * limits.max_acceleration_mps2),
                _ => Some(speed * limits.max_deceleration_mps2),
            },
        }
    }
}

/// A message from the page.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Message {
    /// The controls held now.
    Control {
        /// Sequence number, increasing.
        seq: u64,
        /// Taking over.
        take_over: bool,
        /// Steering axis in `[-1, 1]`.
        lateral: f64,
        /// Speed axis in `[-1, 1]`.
        speed: f64,
    },
    /// Start the next lane change (or go on after a pause).
    Start {
        /// Sequence number, increasing.
        seq: u64,
    },
}

/// What a page's message asks for, once checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request {
    /// New controls.
    Control(Control),
    /// Start or go on.
    Start,
}

/// The checks on one connection's messages: size, rate, form, order.
#[derive(Debug)]
pub struct Inbox {
    last_seq: Option<u64>,
    window_start: Instant,
    in_window: usize,
}

impl Default for Inbox {
    fn default() -> Self {
        Self {
            last_seq: None,
            window_start: Instant::now(),
            in_window: 0,
        }
    }
}

impl Inbox {
    /// The request in `text`, received at `now`, or why it is refused.
    ///
    /// # Errors
    /// A message for the page's error frame.
    pub fn receive(&mut self, text: &str, now: Instant) -> Result<Request, String> {
        if now.duration_since(self.window_start) >= Duration::from_secs(1) {
            self.window_start = now;
            self.in_window = 0;
        }
        self.in_window += 1;
        if self.in_window > MAX_MESSAGES_PER_S {
            return Err(format!(
                "more than {MAX_MESSAGES_PER_S} messages in a second; this one is dropped"
            ));
        }
        if text.len() > MAX_MESSAGE_BYTES {
            return Err(format!(
                "a message of {} bytes; at most {MAX_MESSAGE_BYTES}",
                text.len()
            ));
        }
        let message: Message =
            serde_json::from_str(text).map_err(|e| format!("malformed message: {e}"))?;
        let seq = match message {
            Message::Control { seq, .. } | Message::Start { seq } => seq,
        };
        if self.last_seq.is_some_and(|last| seq <= last) {
            return Err(format!(
                "message {seq} out of order: {} came before",
                self.last_seq.unwrap_or_default()
            ));
        }
        let request = match message {
            Message::Start { .. } => Request::Start,
            Message::Control {
                take_over,
                lateral,
                speed,
                ..
            } => Request::Control(Control {
                take_over,
                lateral: axis("lateral", lateral)?,
                speed: axis("speed", speed)?,
            }),
        };
        self.last_seq = Some(seq);
        Ok(request)
    }
}

/// An axis in `[-1, 1]` as whole steps of 1/1024.
fn axis(name: &str, value: f64) -> Result<i16, String> {
    if !(value.is_finite() && (-1.0..=1.0).contains(&value)) {
        return Err(format!("`{name}` is {value}, expected a number in [-1, 1]"));
    }
    Ok((value * f64::from(AXIS_STEPS)).round() as i16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_messages_are_refused_with_a_reason_and_order_is_kept() {
        let mut inbox = Inbox::default();
        let now = Instant::now();
        let ok = r#"{"type":"control","seq":2,"take_over":true,"lateral":0.5,"speed":-1}"#;
        let request = inbox.receive(ok, now).unwrap();
        assert_eq!(
            request,
            Request::Control(Control {
                take_over: true,
                lateral: 512,
                speed: -1024
            })
        );
        let old = r#"{"type":"start","seq":1}"#;
        assert!(
            inbox
                .receive(old, now)
                .unwrap_err()
                .contains("out of order")
        );
        assert!(
            inbox
                .receive("{not json", now)
                .unwrap_err()
                .contains("malformed")
        );
        let wild = r#"{"type":"control","seq":3,"take_over":false,"lateral":7,"speed":0}"#;
        assert!(
            inbox
                .receive(wild, now)
                .unwrap_err()
                .contains("`lateral` is 7")
        );
        let big = format!(r#"{{"type":"start","seq":4,"pad":"{}"}}"#, "x".repeat(2000));
        assert!(inbox.receive(&big, now).unwrap_err().contains("bytes"));
        let flood = (0..MAX_MESSAGES_PER_S)
            .map(|i| inbox.receive(&format!(r#"{{"type":"start","seq":{}}}"#, 10 + i), now))
            .filter(Result::is_err)
            .count();
        assert!(flood > 0);
        let later = now + Duration::from_secs(2);
        assert!(
            inbox
                .receive(r#"{"type":"start","seq":100000}"#, later)
                .is_ok()
        );
    }
}
