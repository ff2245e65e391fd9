# A DH table with one unusable row is not converted at all (a chain from the other rows would mislead).
robot planar {
    dh {
        row a=0.3 m, alpha=1e307rad, d=0 m   # expect: error[out-of-range] 'alpha' = 1e+307 rad is out of range (at most 1e+06 rad)
        row a=0 m, alpha=0deg, d=0.075 m
    }
}
