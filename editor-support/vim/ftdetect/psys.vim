" .psys files are psys programs.
autocmd BufRead,BufNewFile *.psys setfiletype psys
