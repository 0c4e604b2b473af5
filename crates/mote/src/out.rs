//! Standard output and standard error without panics: [`say!`] and
//! [`tell!`] write lines through `mote_front::terminal` (a failed write is
//! remembered and ends the program with a message and status 1, never a
//! panic). A stdout or stderr closed at the start (`>&-`) is reopened on
//! /dev/null by Rust's runtime before `main`, so it takes lines as
//! /dev/null does, and no file mote opens can take its number.

/// `println!` that never panics (`mote_front::terminal::say`).
macro_rules! say {
    () => { mote_front::terminal::say(format_args!("")) };
    ($($t:tt)*) => { mote_front::terminal::say(format_args!($($t)*)) };
}

/// `eprintln!` that never panics (`mote_front::terminal::tell`).
macro_rules! tell {
    () => { mote_front::terminal::tell(format_args!("")) };
    ($($t:tt)*) => { mote_front::terminal::tell(format_args!($($t)*)) };
}
