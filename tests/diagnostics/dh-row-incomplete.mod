# Every DH row needs a, alpha and d (theta is optional). A table with an incomplete row is not
# converted at all: a chain from the other rows would only mislead.
robot planar {
    dh {
        row a=0.3 m, alpha=0deg, d=0 m
        row a=0.22 m, d=0 m   # expect: error[dh-row-incomplete] DH row 2 lacks alpha
    }
}
