"""What would make it pass: the smallest combined change, the staged search over settings, rate limiter and hardware, the finish."""
