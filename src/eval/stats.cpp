#include "eval/stats.hpp"
