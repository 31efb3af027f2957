//! Reading CommonRoad scenarios and finding their lane changes.
