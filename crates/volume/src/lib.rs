//! Motion volumes of cables (see issue 6).
