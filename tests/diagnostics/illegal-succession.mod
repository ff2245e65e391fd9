robot farm {
    chain H1 - L3 -
          H1 - L1   # expect: error[illegal-succession]
}
