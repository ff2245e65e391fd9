robot farm {
    chain H1 - H4(pivot=-90deg, port=40deg) - L4   # expect: error[twist-not-realisable] H4 port 40deg cannot be set: it is set in steps of 15deg
}
