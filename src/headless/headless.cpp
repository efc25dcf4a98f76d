#include "headless/headless.h"
