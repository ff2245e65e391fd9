robot longreach {
    chain H1 - H3(link=600mm) - L1   # expect: error[link-length-range]
}
