design cell {
    target a at (0.3, 0, 0.2) m
    units 2 to 7   # expect: error[design-bound] chains of 7 units cannot be assembled from this library
}
