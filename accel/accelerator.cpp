// Out-of-line anchor for the accelerator interface's vtable.
#include "accel/accelerator.hpp"
