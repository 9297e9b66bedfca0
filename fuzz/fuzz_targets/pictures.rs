#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| slipgate_fuzz::pictures(data));
