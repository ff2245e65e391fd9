robot farm {
    chain H1 - H4(pivot=-90) - L4   # expect: error[missing-unit] 'pivot' needs a unit
}
