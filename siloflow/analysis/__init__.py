"""Analysis: reading particle dumps into frames, and pure computations on frames and fields."""
