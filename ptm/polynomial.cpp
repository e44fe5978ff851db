#include "ptm/polynomial.h"
