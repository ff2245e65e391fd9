# A file with one mistake of several kinds, for the lint output formats' golden files.
robot cell {
    chain H1 - L4(port=40deg, pivot=3) - H1
    pose home (0, 0) deg
}
