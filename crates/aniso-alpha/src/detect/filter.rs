//! Path filter.
