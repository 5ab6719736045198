// placeholder so the target has a source; removed once real sources land
