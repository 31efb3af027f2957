//! Writing CommonRoad scenarios and solution files.
