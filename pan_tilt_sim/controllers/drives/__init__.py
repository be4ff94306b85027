"""Mobile-base drive controllers: diff drive, mecanum, omni wheel and tricycle."""
