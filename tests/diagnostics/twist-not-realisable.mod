robot farm {
    chain H1 - H4(pivot=-90deg, port=40deg) - L4   # expect: error[twist-not-realisable]
}
