robot longreach {
    chain H1 - H3(link=600mm) - L1   # expect: error[link-length-range] link length 0.6 m is outside 0.05 m..0.5 m
}
