design cell {
    target a at (0.3, 0, 0.2) m
    links 100 mm to 300 mm step 1e-320 m   # expect: error[design-bound] over a trillion link lengths per link unit are too many to search
}
